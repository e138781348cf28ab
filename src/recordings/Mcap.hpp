#pragma once
// Private to recordings: the MCAP reader behind Recording::Open (ROS 2's default container since
// Iron; mcap.dev/spec).

#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "FileReader.hpp"
#include "TopicTable.hpp"
#include "strata/recordings/Recording.hpp"

namespace strata::recordings::detail {

class Mcap final : public Recording {
public:
    explicit Mcap(const std::filesystem::path& path);
    ~Mcap() override;

    [[nodiscard]] const RecordingInfo& info() const override { return info_; }
    void Read(const std::vector<std::string>& topics, const Visitor& visit) const override;
    void ReadMessage(const MessageLocation& location, const Visitor& visit) const override;

    /// MessageLocation::record of a message outside any chunk (location.chunk is then the
    /// message record's own offset).
    static constexpr uint64_t kUnchunked = ~uint64_t{0};

private:
    // Where messages are: a chunk record, or one message record outside chunks, in file order.
    struct Block {
        uint64_t offset = 0;
        bool chunk = true;
        std::set<uint16_t> channels;  // those with messages in it; empty: not known, read it
    };
    struct Record {
        uint8_t op = 0;
        std::vector<uint8_t> content;
        uint64_t end = 0;  // offset of the next record
    };

    [[nodiscard]] Record ReadRecord(uint64_t offset, bool with_content) const;
    // The uncompressed, CRC-checked records of a chunk: `bytes` from `begin` on (an uncompressed
    // chunk's records stay where they were read, inside its record).
    struct ChunkBytes {
        std::vector<uint8_t> bytes;
        size_t begin = 0;
        [[nodiscard]] const uint8_t* data() const { return bytes.data() + begin; }
        [[nodiscard]] size_t size() const { return bytes.size() - begin; }
    };
    [[nodiscard]] ChunkBytes ChunkRecords(uint64_t offset, std::string* compression) const;
    void ReadSummary(uint64_t start, uint64_t end);
    void ScanData(uint64_t end);
    void AddSchema(const uint8_t* content, size_t size, const std::string& where);
    void AddChannel(const uint8_t* content, size_t size, const std::string& where);
    // Visits a message record's content; `channel` from ChannelOf (so it holds a header).
    void Visit(uint16_t channel, const uint8_t* content, size_t size, MessageLocation location,
               const Visitor& visit, const std::string& where) const;

    FileReader file_;
    RecordingInfo info_;
    TopicTable topics_;                        // channels
    std::map<uint16_t, std::string> schemas_;  // schema id -> name (the message type)
    std::vector<Block> blocks_;
    uint64_t data_start_ = 0;
    mutable std::mutex cache_mutex_;  // ReadMessage's last chunk, uncompressed
    mutable uint64_t cached_chunk_ = 0;
    mutable ChunkBytes cached_;
};

}  // namespace strata::recordings::detail
