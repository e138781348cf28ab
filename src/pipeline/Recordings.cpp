#include "strata/pipeline/Recordings.hpp"

#include "strata/recordings/Recording.hpp"
#include "strata/recordings/TransformTree.hpp"

namespace strata::pipeline {

nlohmann::json DescribeRecording(const std::filesystem::path& path) {
    const auto recording = recordings::Recording::Open(path);
    const recordings::RecordingInfo& info = recording->info();
    nlohmann::json j;
    j["path"] = path.string();
    j["format"] = info.format;
    j["indexed"] = info.indexed;
    j["bytes"] = info.bytes;
    j["chunks"] = info.chunks;
    j["compression"] = info.compression;
    j["start"] = recordings::FormatStamp(info.start_ns);
    j["end"] = recordings::FormatStamp(info.end_ns);
    j["duration_s"] = static_cast<double>(info.end_ns - info.start_ns) * 1e-9;
    uint64_t messages = 0;
    j["topics"] = nlohmann::json::array();
    for (const recordings::Topic& t : info.topics) {
        j["topics"].push_back(
            {{"name", t.name},
             {"type", t.type},
             {"encoding", t.encoding == recordings::Encoding::kRos1 ? "ros1" : "cdr"},
             {"messages", t.messages}});
        messages += t.messages;
    }
    j["messages"] = messages;
    const recordings::TransformTree tree = recordings::ReadTransformTree(*recording);
    j["frames"] = tree.Frames();
    j["tf_edges"] = nlohmann::json::array();
    for (const recordings::TransformTree::EdgeSummary& e : tree.Edges()) {
        nlohmann::json edge = {{"parent", e.parent}, {"child", e.child}, {"static", e.is_static}};
        if (!e.is_static) {
            edge["samples"] = e.samples;
            edge["first"] = recordings::FormatStamp(e.first_ns);
            edge["last"] = recordings::FormatStamp(e.last_ns);
        }
        j["tf_edges"].push_back(edge);
    }
    return j;
}

}  // namespace strata::pipeline
