#pragma once
// Private to recordings: rosbag2's SQLite storage (ROS 2 up to Humble's default): a folder with
// metadata.yaml and one or more .db3 files, or a single .db3 file.

#include <mutex>
#include <string>
#include <vector>

#include "TopicTable.hpp"
#include "strata/recordings/Recording.hpp"

struct sqlite3;

namespace strata::recordings::detail {

class Rosbag2Sqlite final : public Recording {
public:
    explicit Rosbag2Sqlite(const std::filesystem::path& path);
    ~Rosbag2Sqlite() override;
    Rosbag2Sqlite(const Rosbag2Sqlite&) = delete;
    Rosbag2Sqlite& operator=(const Rosbag2Sqlite&) = delete;

    [[nodiscard]] const RecordingInfo& info() const override { return info_; }
    void Read(const std::vector<std::string>& topics, const Visitor& visit) const override;
    /// MessageLocation: `chunk` the file's index in the folder, `record` the message's row id.
    void ReadMessage(const MessageLocation& location, const Visitor& visit) const override;

private:
    struct Database {
        std::string name;
        sqlite3* db = nullptr;
    };
    // A stream of TopicTable: the file's index and its topic id.
    static uint32_t Stream(size_t file, int64_t topic_id);
    // A message's CDR bytes: `data` itself, or decompressed into buffer_ when zstd-compressed
    // (`size` updated). Called under mutex_; valid until the next call.
    const uint8_t* Payload(const uint8_t* data, size_t* size, const std::string& file) const;

    std::vector<Database> files_;
    RecordingInfo info_;
    TopicTable topics_;
    mutable std::mutex mutex_;             // one statement at a time on a connection
    mutable std::vector<uint8_t> buffer_;  // a decompressed message
};

}  // namespace strata::recordings::detail
