// MCAP (mcap.dev/spec): magic, a Header record, the data section (records, or Chunks holding
// Schema, Channel and Message records compressed whole: none, lz4 or zstd, each with a CRC-32 of
// its uncompressed records), optionally a summary section (Schema, Channel, Chunk Index and
// Statistics copies) and summary offsets, the Footer and the magic again. A record is
// <u8 opcode><u64 length><content>; strings and maps carry a u32 byte length. With a summary the
// recording is opened from it alone; without one (or without chunk indexes and statistics) every
// record of the data section is scanned once.
#include "Mcap.hpp"

#include <algorithm>
#include <cstring>

#include "Decompress.hpp"
#include "strata/core/Error.hpp"

namespace strata::recordings::detail {
namespace {

constexpr uint8_t kMcapMagic[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};
constexpr size_t kFooterBytes = 1 + 8 + 20;  // opcode, length, summary_start, offset start, crc
enum : uint8_t {
    kHeader = 0x01,
    kFooter = 0x02,
    kSchema = 0x03,
    kChannel = 0x04,
    kMessage = 0x05,
    kChunk = 0x06,
    kChunkIndex = 0x08,
    kStatistics = 0x0B,
    kDataEnd = 0x0F,
};
// No record but a chunk (or an attachment, never read) comes near this; a longer one is damage,
// refused before its memory is taken.
constexpr uint64_t kMaxRecordBytes = uint64_t{1} << 32;

std::string McapString(core::ByteCursor& in, const char* what) {
    const auto n = in.Read<uint32_t>(what);
    return std::string(reinterpret_cast<const char*>(in.Take(n, what)), n);
}

// A message record's content: channel, sequence, log time, publish time, then the data.
constexpr size_t kMessageHeaderBytes = 2 + 4 + 8 + 8;

// Calls f(opcode, content, length, offset) for each record of a chunk's uncompressed records.
template <typename F>
void ForEachRecord(const uint8_t* data, size_t size, const std::string& where, F&& f) {
    core::ByteCursor in(data, size, where);
    while (in.remaining() > 0) {
        const size_t at = in.position();
        const auto op = in.Read<uint8_t>("record opcode");
        const auto length = in.Read<uint64_t>("record length");
        if (length > in.remaining()) in.Fail("a record in the chunk runs past its end");
        f(op, in.Take(length, "record"), static_cast<size_t>(length), at);
    }
}

// The channel of a message record (FormatError when it is too short to be one).
uint16_t ChannelOf(const uint8_t* content, size_t size, const std::string& where) {
    if (size < kMessageHeaderBytes) {
        Fail(where, "message record of " + std::to_string(size) + " bytes");
    }
    return core::LoadScalar<uint16_t>(content, false);
}

}  // namespace

Mcap::Mcap(const std::filesystem::path& path) : file_(path) {
    const std::string& name = file_.name();
    info_.path = path;
    info_.format = "MCAP";
    info_.bytes = file_.size();
    std::vector<uint8_t> bytes;
    if (file_.size() < sizeof(kMcapMagic)) Fail(name, "not an MCAP file (too short for its magic)");
    file_.Read(0, sizeof(kMcapMagic), bytes, "magic");
    if (std::memcmp(bytes.data(), kMcapMagic, 5) != 0) {
        Fail(name, "not an MCAP file: it does not start with MCAP's magic");
    }
    if (bytes[5] != kMcapMagic[5]) {
        Fail(name, "MCAP major version " + std::string(1, static_cast<char>(bytes[5])) +
                       ", strata reads version 0");
    }
    const Record header = ReadRecord(sizeof(kMcapMagic), true);
    if (header.op != kHeader)
        Fail(At(name, "record", sizeof(kMcapMagic)), "the first record is not the Header");
    data_start_ = header.end;
    // The footer and the closing magic: missing when the recorder died (`mcap recover` rewrites
    // such a file), and then refused as truncated.
    if (file_.size() < data_start_ + kFooterBytes + sizeof(kMcapMagic)) {
        Fail(name, "truncated: no room for the footer after the header");
    }
    const uint64_t footer_at = file_.size() - sizeof(kMcapMagic) - kFooterBytes;
    file_.Read(footer_at, kFooterBytes + sizeof(kMcapMagic), bytes, "footer");
    if (std::memcmp(bytes.data() + kFooterBytes, kMcapMagic, sizeof(kMcapMagic)) != 0 ||
        bytes[0] != kFooter || core::LoadScalar<uint64_t>(bytes.data() + 1, false) != 20) {
        Fail(name,
             "truncated or damaged: it does not end with a footer and MCAP's magic (was the "
             "recording cut? `mcap recover` rewrites such a file)");
    }
    const auto summary_start = core::LoadScalar<uint64_t>(bytes.data() + 9, false);
    const auto summary_offset_start = core::LoadScalar<uint64_t>(bytes.data() + 17, false);
    const auto summary_crc = core::LoadScalar<uint32_t>(bytes.data() + 25, false);
    const uint64_t summary_end = summary_offset_start != 0 ? summary_offset_start : footer_at;
    if (summary_start != 0 &&
        (summary_start < data_start_ || summary_start > summary_end || summary_end > footer_at)) {
        Fail(name, "damaged footer: the summary at byte " + std::to_string(summary_start) +
                       " lies outside the file's sections");
    }
    if (summary_start != 0 && summary_crc != 0) {
        // The summary and summary offsets, and the footer up to its CRC.
        file_.Read(summary_start, footer_at + 1 + 8 + 16 - summary_start, bytes, "summary");
        if (Crc32(bytes.data(), bytes.size()) != summary_crc) {
            Fail(name, "damaged summary: its CRC-32 does not match the footer's");
        }
    }
    if (summary_start != 0) ReadSummary(summary_start, summary_end);
    if (blocks_.empty()) {
        // No usable index (no summary, or no chunk indexes and counts in it): every record of
        // the data section, once.
        topics_ = TopicTable();
        schemas_.clear();
        info_.chunks = 0;
        info_.start_ns = info_.end_ns = 0;
        info_.compression.clear();
        ScanData(summary_start != 0 ? summary_start : footer_at);
    }
    topics_.Finish(info_);
}

Mcap::~Mcap() = default;

Mcap::Record Mcap::ReadRecord(uint64_t offset, bool with_content) const {
    Record r;
    std::vector<uint8_t> prefix;
    file_.Read(offset, 9, prefix, "record opcode and length");
    r.op = prefix[0];
    const auto length = core::LoadScalar<uint64_t>(prefix.data() + 1, false);
    if (length > kMaxRecordBytes || length > file_.size() - offset - 9) {
        Fail(file_.name(), "truncated: the record at byte " + std::to_string(offset) +
                               " declares " + std::to_string(length) + " bytes, the file has " +
                               std::to_string(file_.size() - offset - 9) + " more");
    }
    if (with_content) file_.Read(offset + 9, length, r.content, "record");
    r.end = offset + 9 + length;
    return r;
}

void Mcap::AddSchema(const uint8_t* content, size_t size, const std::string& where) {
    core::ByteCursor in(content, size, where);
    const auto id = in.Read<uint16_t>("schema id");
    const std::string name = McapString(in, "schema name");
    if (id != 0) schemas_[id] = name;  // id 0 is invalid: ignored, as the spec says
}

void Mcap::AddChannel(const uint8_t* content, size_t size, const std::string& where) {
    core::ByteCursor in(content, size, where);
    const auto id = in.Read<uint16_t>("channel id");
    const auto schema = in.Read<uint16_t>("channel schema id");
    const std::string topic = McapString(in, "channel topic");
    const std::string encoding = McapString(in, "channel message encoding");
    const auto it = schemas_.find(schema);
    if (schema != 0 && it == schemas_.end()) {
        Fail(where, "channel " + std::to_string(id) + " (" + topic + ") names schema " +
                        std::to_string(schema) + ", which comes nowhere before it");
    }
    topics_.Add(id, topic, schema == 0 ? std::string() : it->second, EncodingOf(encoding), where);
}

void Mcap::ReadSummary(uint64_t start, uint64_t end) {
    const std::string& name = file_.name();
    std::set<std::string> compressions;
    bool counted = false;
    for (uint64_t offset = start; offset < end;) {
        const Record r = ReadRecord(offset, true);
        const std::string where = At(name, "summary record", offset);
        core::ByteCursor in(r.content.data(), r.content.size(), where);
        if (r.op == kSchema) {
            AddSchema(r.content.data(), r.content.size(), where);
        } else if (r.op == kChannel) {
            AddChannel(r.content.data(), r.content.size(), where);
        } else if (r.op == kChunkIndex) {
            const auto start_ns = in.Read<uint64_t>("message start time");
            const auto end_ns = in.Read<uint64_t>("message end time");
            Block block;
            block.offset = in.Read<uint64_t>("chunk start offset");
            static_cast<void>(in.Read<uint64_t>("chunk length"));
            const auto map_bytes = in.Read<uint32_t>("message index offsets");
            if (map_bytes % 10 != 0)
                in.Fail("message index offsets of " + std::to_string(map_bytes) + " bytes");
            core::ByteCursor map(in.Take(map_bytes, "message index offsets"), map_bytes, where);
            while (map.remaining() > 0) {
                block.channels.insert(map.Read<uint16_t>("channel id"));
                static_cast<void>(map.Read<uint64_t>("message index offset"));
            }
            static_cast<void>(in.Read<uint64_t>("message index length"));
            compressions.insert(McapString(in, "compression"));
            if (block.offset < data_start_ || block.offset >= start) {
                in.Fail("chunk offset " + std::to_string(block.offset) + " lies outside the data");
            }
            if (info_.chunks == 0 || static_cast<int64_t>(start_ns) < info_.start_ns) {
                info_.start_ns = static_cast<int64_t>(start_ns);
            }
            info_.end_ns = std::max(info_.end_ns, static_cast<int64_t>(end_ns));
            ++info_.chunks;
            blocks_.push_back(std::move(block));
        } else if (r.op == kStatistics) {
            static_cast<void>(in.Read<uint64_t>("message count"));
            in.Skip(2 + 4 + 4 + 4 + 4, "statistics counts");
            const auto first = in.Read<uint64_t>("message start time");
            const auto last = in.Read<uint64_t>("message end time");
            const auto map_bytes = in.Read<uint32_t>("channel message counts");
            if (map_bytes % 10 != 0)
                in.Fail("channel message counts of " + std::to_string(map_bytes) + " bytes");
            core::ByteCursor map(in.Take(map_bytes, "channel message counts"), map_bytes, where);
            while (map.remaining() > 0) {
                const auto channel = map.Read<uint16_t>("channel id");
                topics_.Count(channel, map.Read<uint64_t>("message count"));
                counted = true;
            }
            info_.start_ns = static_cast<int64_t>(first);
            info_.end_ns = static_cast<int64_t>(last);
        }
        offset = r.end;
    }
    if (!counted) {
        // Without the statistics' counts the index says where messages are, not how many: the
        // caller scans the data instead.
        blocks_.clear();
        return;
    }
    std::sort(blocks_.begin(), blocks_.end(),
              [](const Block& a, const Block& b) { return a.offset < b.offset; });
    for (const std::string& c : compressions) {
        info_.compression += (info_.compression.empty() ? "" : ", ") + (c.empty() ? "none" : c);
    }
}

void Mcap::ScanData(uint64_t end) {
    info_.indexed = false;
    std::set<std::string> compressions;
    // After ChannelOf: the record holds a message header.
    const auto on_message = [&](uint16_t channel, const uint8_t* content, size_t,
                                const std::string& where, Block& block) {
        if (!topics_.Has(channel)) {
            Fail(where,
                 "a message of channel " + std::to_string(channel) + " before its channel record");
        }
        topics_.Count(channel, 1);
        const auto t = static_cast<int64_t>(core::LoadScalar<uint64_t>(content + 6, false));
        if (info_.start_ns == 0 || t < info_.start_ns) info_.start_ns = t;
        info_.end_ns = std::max(info_.end_ns, t);
        block.channels.insert(channel);
    };
    for (uint64_t offset = data_start_; offset < end;) {
        const Record r = ReadRecord(offset, true);
        const std::string where = At(file_.name(), "record", offset);
        if (r.op == kDataEnd || r.op == kFooter) break;
        if (r.op == kSchema) {
            AddSchema(r.content.data(), r.content.size(), where);
        } else if (r.op == kChannel) {
            AddChannel(r.content.data(), r.content.size(), where);
        } else if (r.op == kMessage) {
            Block block{offset, false, {}};
            on_message(ChannelOf(r.content.data(), r.content.size(), where), r.content.data(),
                       r.content.size(), where, block);
            blocks_.push_back(std::move(block));
        } else if (r.op == kChunk) {
            std::string compression;
            const ChunkBytes records = ChunkRecords(offset, &compression);
            compressions.insert(compression.empty() ? "none" : compression);
            Block block{offset, true, {}};
            ForEachRecord(records.data(), records.size(), where,
                          [&](uint8_t op, const uint8_t* content, size_t length, size_t at) {
                              const std::string at_where =
                                  where + ", record at byte " + std::to_string(at);
                              if (op == kSchema) AddSchema(content, length, at_where);
                              if (op == kChannel) AddChannel(content, length, at_where);
                              if (op == kMessage) {
                                  on_message(ChannelOf(content, length, at_where), content, length,
                                             at_where, block);
                              }
                          });
            ++info_.chunks;
            blocks_.push_back(std::move(block));
        }
        offset = r.end;
    }
    for (const std::string& c : compressions) {
        info_.compression += (info_.compression.empty() ? "" : ", ") + c;
    }
}

Mcap::ChunkBytes Mcap::ChunkRecords(uint64_t offset, std::string* compression) const {
    Record r = ReadRecord(offset, true);
    const std::string where = At(file_.name(), "chunk", offset);
    if (r.op != kChunk) Fail(where, "no chunk record starts there");
    core::ByteCursor in(r.content.data(), r.content.size(), where);
    in.Skip(16, "message start and end times");
    const auto size = in.Read<uint64_t>("uncompressed size");
    const auto crc = in.Read<uint32_t>("uncompressed CRC");
    *compression = McapString(in, "compression");
    const auto records_size = in.Read<uint64_t>("records length");
    if (records_size > in.remaining()) {
        in.Fail("records of " + std::to_string(records_size) + " bytes declared, " +
                std::to_string(in.remaining()) + " in the record");
    }
    const uint8_t* records = in.Take(records_size, "records");
    CheckDeclaredSize(records_size, size, where);
    ChunkBytes plain;
    if (compression->empty()) {
        if (records_size != size) {
            Fail(where, "uncompressed chunk of " + std::to_string(records_size) +
                            " bytes declares " + std::to_string(size));
        }
        plain.begin = static_cast<size_t>(records - r.content.data());
        plain.bytes = std::move(r.content);
    } else if (*compression == "lz4") {
        DecompressLz4Frame(records, records_size, size, plain.bytes, where);
    } else if (*compression == "zstd") {
        DecompressZstd(records, records_size, size, plain.bytes, where);
    } else {
        Fail(where, "unknown compression '" + *compression + "' (strata reads none, lz4 and zstd)");
    }
    if (crc != 0 && Crc32(plain.data(), plain.size()) != crc) {
        Fail(where, "damaged chunk: the CRC-32 of its records does not match its header's");
    }
    return plain;
}

void Mcap::Visit(uint16_t channel, const uint8_t* content, size_t size, MessageLocation location,
                 const Visitor& visit, const std::string& where) const {
    const Topic* topic = topics_.TopicOf(channel, info_);
    if (topic == nullptr)
        Fail(where, "a message of channel " + std::to_string(channel) + ", which is not declared");
    const auto t = static_cast<int64_t>(core::LoadScalar<uint64_t>(content + 6, false));
    visit(Message{topic, t, content + kMessageHeaderBytes, size - kMessageHeaderBytes, location});
}

void Mcap::Read(const std::vector<std::string>& topics, const Visitor& visit) const {
    const std::set<uint32_t> wanted = topics_.Streams(topics, info_);
    for (const Block& block : blocks_) {
        if (!block.channels.empty() &&
            std::none_of(block.channels.begin(), block.channels.end(),
                         [&](uint16_t c) { return wanted.count(c) != 0; })) {
            continue;
        }
        const std::string where = At(file_.name(), block.chunk ? "chunk" : "message", block.offset);
        if (!block.chunk) {
            const Record r = ReadRecord(block.offset, true);
            const uint16_t channel = ChannelOf(r.content.data(), r.content.size(), where);
            if (wanted.count(channel) != 0) {
                Visit(channel, r.content.data(), r.content.size(), {block.offset, kUnchunked},
                      visit, where);
            }
            continue;
        }
        std::string compression;
        const ChunkBytes records = ChunkRecords(block.offset, &compression);
        ForEachRecord(records.data(), records.size(), where,
                      [&](uint8_t op, const uint8_t* content, size_t length, size_t at) {
                          if (op != kMessage) return;
                          const std::string at_where =
                              where + ", record at byte " + std::to_string(at);
                          const uint16_t channel = ChannelOf(content, length, at_where);
                          if (wanted.count(channel) != 0) {
                              Visit(channel, content, length, {block.offset, at}, visit, at_where);
                          }
                      });
    }
}

void Mcap::ReadMessage(const MessageLocation& location, const Visitor& visit) const {
    const std::string where = At(file_.name(), "message", location.chunk);
    if (location.record == kUnchunked) {
        const Record r = ReadRecord(location.chunk, true);
        if (r.op != kMessage) Fail(where, "no message record starts there");
        Visit(ChannelOf(r.content.data(), r.content.size(), where), r.content.data(),
              r.content.size(), location, visit, where);
        return;
    }
    const std::lock_guard<std::mutex> lock(cache_mutex_);
    if (cached_chunk_ != location.chunk || cached_.bytes.empty()) {
        std::string compression;
        cached_ = ChunkRecords(location.chunk, &compression);
        cached_chunk_ = location.chunk;
    }
    core::ByteCursor in(cached_.data(), cached_.size(), where);
    in.Seek(location.record, "the message");
    const auto op = in.Read<uint8_t>("record opcode");
    const auto length = in.Read<uint64_t>("record length");
    if (op != kMessage || length > in.remaining()) Fail(where, "no message record there");
    const uint8_t* content = in.Take(length, "record");
    Visit(ChannelOf(content, length, where), content, length, location, visit, where);
}

}  // namespace strata::recordings::detail
