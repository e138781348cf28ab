#pragma once
// Robot recordings as containers: which topics a recording holds and the bytes of their messages.
// ROS 1 bags (format 2.0; chunks uncompressed, bz2 or lz4), MCAP (chunks uncompressed, lz4 or
// zstd) and rosbag2's SQLite storage are read here; Messages.hpp decodes the
// messages that carry maps and TransformTree.hpp composes their poses (docs/recordings.md).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace strata::recordings {

/// @brief How a topic's messages are serialized: ROS 1's, ROS 2's CDR (with its 4-byte
/// encapsulation header), or another (MCAP's json, protobuf, ...: listed, not decoded).
enum class Encoding : uint8_t { kRos1, kCdr, kOther };

/// @brief One topic of a recording, with everything recorded on it.
struct Topic {
    std::string name;  ///< "/velodyne_points"
    std::string type;  ///< "sensor_msgs/PointCloud2" (ROS 2: "sensor_msgs/msg/PointCloud2")
    Encoding encoding = Encoding::kRos1;
    uint64_t messages = 0;
};

/// @brief Where a message lies in its recording, to read it again (Recording::ReadMessage).
struct MessageLocation {
    uint64_t chunk = 0;   ///< the chunk's position in the file
    uint64_t record = 0;  ///< the record's position in the chunk's uncompressed bytes
};

/// @brief One recorded message. `data` is valid only while the visitor that receives it runs.
struct Message {
    const Topic* topic = nullptr;
    int64_t log_time_ns = 0;  ///< when the recorder received it (ns since the epoch)
    const uint8_t* data = nullptr;
    size_t size = 0;
    MessageLocation location;
};

/// @brief What a recording holds, read from its index (or from a scan of the whole file when it
/// has none).
struct RecordingInfo {
    std::filesystem::path path;
    std::string format;       ///< "ROS 1 bag 2.0", "MCAP" or "rosbag2 SQLite"
    std::string compression;  ///< the chunks' compressions, e.g. "lz4" or "none, bz2"
    uint64_t bytes = 0;       ///< the file's size
    uint64_t chunks = 0;
    bool indexed = true;   ///< false: the recording was cut short and its messages were counted
    int64_t start_ns = 0;  ///< log time of the first message (0 when there is none)
    int64_t end_ns = 0;    ///< log time of the last message
    std::vector<Topic> topics;  ///< sorted by name

    /// @brief The topic called `name`, or nullptr.
    [[nodiscard]] const Topic* Find(const std::string& name) const;
};

/// @brief A recording opened for reading. Reading streams: one chunk is in memory at a time, so
/// a recording larger than memory is read in a bounded working set.
class Recording {
public:
    using Visitor = std::function<void(const Message&)>;

    virtual ~Recording() = default;

    /// @brief Opens a ROS 1 bag, an MCAP file or a rosbag2 SQLite bag (a `.db3` file, or a folder
    /// with metadata.yaml), recognised by their first bytes.
    /// @throw NotFoundError when it does not exist; FormatError naming the file when it is not a
    /// recording this build reads or its header is damaged; IoError when it cannot be read.
    [[nodiscard]] static std::unique_ptr<Recording> Open(const std::filesystem::path& path);

    [[nodiscard]] virtual const RecordingInfo& info() const = 0;

    /// @brief Calls `visit` for every message on `topics` (every topic when empty), chunk by
    /// chunk in the order they were written, and within a chunk as recorded.
    /// @throw NotFoundError naming a topic the recording does not hold (and the ones it does);
    /// FormatError naming the file and the byte offset of a damaged record; whatever `visit`
    /// throws.
    virtual void Read(const std::vector<std::string>& topics, const Visitor& visit) const = 0;

    /// @brief Calls `visit` for the one message at `location` (from a message Read gave). The
    /// last chunk read is kept, so that reading a chunk's messages one by one decompresses it
    /// once. Safe to call from several threads.
    /// @throw FormatError when no message starts there.
    virtual void ReadMessage(const MessageLocation& location, const Visitor& visit) const = 0;
};

/// @brief "sec.nanosec" of a time in ns since the epoch, for messages.
[[nodiscard]] std::string FormatStamp(int64_t ns);

}  // namespace strata::recordings
