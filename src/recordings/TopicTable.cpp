#include "TopicTable.hpp"

#include <algorithm>

#include "FileReader.hpp"
#include "strata/core/Error.hpp"

namespace strata::recordings::detail {

Encoding EncodingOf(const std::string& name) {
    if (name == "cdr") return Encoding::kCdr;
    if (name == "ros1") return Encoding::kRos1;
    return Encoding::kOther;
}

void TopicTable::Add(uint32_t id, const std::string& topic, const std::string& type,
                     Encoding encoding, const std::string& where) {
    const auto known = topic_of_.find(id);
    if (known != topic_of_.end()) {
        if (known->second != topic) {
            Fail(where, "stream " + std::to_string(id) + " is recorded for two topics, " +
                            known->second + " and " + topic);
        }
        return;
    }
    const auto [it, added] = topics_.try_emplace(topic, Topic{topic, type, encoding, 0});
    if (!added && (it->second.type != type || it->second.encoding != encoding)) {
        Fail(where,
             "topic " + topic + " is recorded with two types, " + it->second.type + " and " + type);
    }
    topic_of_[id] = topic;
}

void TopicTable::Count(uint32_t id, uint64_t n) {
    const auto it = topic_of_.find(id);
    if (it != topic_of_.end()) topics_.at(it->second).messages += n;
}

void TopicTable::Finish(RecordingInfo& info) {
    info.topics.clear();
    std::map<std::string, size_t> position;
    for (const auto& [name, topic] : topics_) {
        position[name] = info.topics.size();
        info.topics.push_back(topic);
    }
    for (const auto& [id, topic] : topic_of_) index_[id] = position.at(topic);
}

const Topic* TopicTable::TopicOf(uint32_t id, const RecordingInfo& info) const {
    const auto it = index_.find(id);
    return it == index_.end() ? nullptr : &info.topics[it->second];
}

std::set<uint32_t> TopicTable::Streams(const std::vector<std::string>& topics,
                                       const RecordingInfo& info) const {
    for (const std::string& t : topics) {
        if (info.Find(t) == nullptr) {
            std::string names;
            for (const Topic& k : info.topics) names += (names.empty() ? "" : ", ") + k.name;
            throw NotFoundError(info.path.string() + ": no topic " + t + " (it has " +
                                (names.empty() ? "none" : names) + ")");
        }
    }
    std::set<uint32_t> streams;
    for (const auto& [id, topic] : topic_of_) {
        if (topics.empty() || std::find(topics.begin(), topics.end(), topic) != topics.end()) {
            streams.insert(id);
        }
    }
    return streams;
}

}  // namespace strata::recordings::detail
