#pragma once
// Private to recordings: what every container keeps of its streams. A ROS 1 bag calls them
// connections, MCAP channels; several may carry one topic. The table maps each to its topic in a
// RecordingInfo, counts messages, and answers which streams a list of topics asks for.

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "strata/recordings/Recording.hpp"

namespace strata::recordings::detail {

/// @brief The Encoding of a serialization's name in MCAP and rosbag2 ("cdr", "ros1", others).
[[nodiscard]] Encoding EncodingOf(const std::string& name);

class TopicTable {
public:
    /// @brief Registers stream `id` on `topic`; again with the same topic is a no-op.
    /// @throw FormatError naming `where` when the stream was registered for another topic, or
    /// the topic was registered with another type or encoding.
    void Add(uint32_t id, const std::string& topic, const std::string& type, Encoding encoding,
             const std::string& where);

    [[nodiscard]] bool Has(uint32_t id) const { return topic_of_.count(id) != 0; }

    /// @brief Adds `n` messages to the count of stream `id`'s topic.
    void Count(uint32_t id, uint64_t n);

    /// @brief Sorts the topics by name into `info.topics`, with their counts. Call once, after
    /// every Add and Count.
    void Finish(RecordingInfo& info);

    /// @brief The topic of stream `id` in `info` (after Finish), or nullptr.
    [[nodiscard]] const Topic* TopicOf(uint32_t id, const RecordingInfo& info) const;

    /// @brief The streams of `topics` (every stream when empty).
    /// @throw NotFoundError naming `file`, the topic and the topics it has.
    [[nodiscard]] std::set<uint32_t> Streams(const std::vector<std::string>& topics,
                                             const RecordingInfo& info) const;

private:
    std::map<uint32_t, std::string> topic_of_;  // stream -> topic
    std::map<std::string, Topic> topics_;       // by name, until Finish
    std::map<uint32_t, size_t> index_;          // stream -> index into info.topics, after Finish
};

}  // namespace strata::recordings::detail
