#pragma once
// Private to recordings: the ROS 1 bag 2.0 reader behind Recording::Open.

#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "FileReader.hpp"
#include "TopicTable.hpp"
#include "strata/recordings/Recording.hpp"

namespace strata::recordings::detail {

class Ros1Bag final : public Recording {
public:
    explicit Ros1Bag(const std::filesystem::path& path);
    ~Ros1Bag() override;

    [[nodiscard]] const RecordingInfo& info() const override { return info_; }
    void Read(const std::vector<std::string>& topics, const Visitor& visit) const override;
    void ReadMessage(const MessageLocation& location, const Visitor& visit) const override;

private:
    struct Chunk {
        uint64_t position = 0;
        std::set<uint32_t> connections;  // those with messages in it
    };
    using OnMessage = std::function<void(uint32_t conn, int64_t time_ns, const uint8_t* data,
                                         size_t size, uint64_t record)>;
    using OnConnection =
        std::function<void(const uint8_t* header, size_t header_size, const uint8_t* data,
                           size_t data_size, const std::string& where)>;

    void ReadIndex(uint64_t index_pos, uint32_t conn_count, uint32_t chunk_count);
    void ScanRecords();
    void AddConnection(const uint8_t* header, size_t header_size, const uint8_t* data,
                       size_t data_size, const std::string& where);
    // The records of the chunk record (header, data) at `offset`: its data decompressed, or the
    // data itself when it is uncompressed.
    [[nodiscard]] std::vector<uint8_t> Uncompress(const std::vector<uint8_t>& header,
                                                  std::vector<uint8_t>&& data,
                                                  uint64_t offset) const;
    // Calls the callbacks for a chunk's records, in order.
    void VisitChunk(const std::vector<uint8_t>& records, uint64_t offset,
                    const OnMessage& on_message, const OnConnection& on_connection) const;

    FileReader file_;
    RecordingInfo info_;
    uint64_t first_record_ = 0;
    TopicTable topics_;  // connections
    std::vector<Chunk> chunks_;
    // ReadMessage's last chunk, uncompressed.
    mutable std::mutex cache_mutex_;
    mutable uint64_t cached_chunk_ = 0;
    mutable std::vector<uint8_t> cached_;
};

}  // namespace strata::recordings::detail
