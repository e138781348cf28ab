// ROS 1 bag format 2.0 (wiki.ros.org/Bags/Format/2.0): the line "#ROSBAG V2.0\n", a bag header
// record padded to 4 KB, then chunks (each followed by index records), then at the header's
// index_pos the connection records and one chunk info record per chunk. A record is
// <u32 header length><header: fields of u32 length + "name=value"><u32 data length><data>; the
// header's `op` field says what it is. Chunks hold connection and message records, compressed
// whole (none, bz2 or lz4). A bag whose recorder died has index_pos 0: it is read by a scan of
// every record instead of its index.
#include "Ros1Bag.hpp"

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <string_view>

#include "Decompress.hpp"
#include "FileReader.hpp"
#include "strata/core/Error.hpp"

namespace strata::recordings::detail {
namespace {

constexpr std::string_view kMagic = "#ROSBAG V2.0\n";
constexpr uint8_t kOpMessage = 0x02, kOpBagHeader = 0x03, kOpIndex = 0x04, kOpChunk = 0x05,
                  kOpChunkInfo = 0x06, kOpConnection = 0x07;
// No header field or chunk is near these; a length beyond them is damage, refused before any
// allocation.
constexpr uint32_t kMaxHeaderBytes = 1u << 20;

// The fields of a record header (or of a connection record's data), by name.
class Fields {
public:
    Fields(const uint8_t* data, size_t size, std::string where) : where_(std::move(where)) {
        core::ByteCursor in(data, size, where_);
        while (in.remaining() > 0) {
            const auto n = in.Read<uint32_t>("header field length");
            const uint8_t* p = in.Take(n, "header field");
            const auto* eq = static_cast<const uint8_t*>(std::memchr(p, '=', n));
            if (eq == nullptr) Fail(where_, "header field without '='");
            const size_t name_n = static_cast<size_t>(eq - p);
            fields_.emplace(
                std::string(reinterpret_cast<const char*>(p), name_n),
                std::string_view(reinterpret_cast<const char*>(eq + 1), n - name_n - 1));
        }
    }

    [[nodiscard]] bool Has(const std::string& name) const { return fields_.count(name) != 0; }

    [[nodiscard]] std::string_view Bytes(const std::string& name) const {
        const auto it = fields_.find(name);
        if (it == fields_.end()) Fail(where_, "record header without its '" + name + "' field");
        return it->second;
    }

    template <typename T>
    [[nodiscard]] T Scalar(const std::string& name) const {
        const std::string_view b = Bytes(name);
        if (b.size() != sizeof(T)) {
            Fail(where_, "header field '" + name + "' has " + std::to_string(b.size()) +
                             " bytes, not " + std::to_string(sizeof(T)));
        }
        return core::LoadScalar<T>(reinterpret_cast<const uint8_t*>(b.data()), false);
    }

    [[nodiscard]] std::string String(const std::string& name) const {
        return std::string(Bytes(name));
    }

    [[nodiscard]] uint8_t Op() const { return Scalar<uint8_t>("op"); }

private:
    std::map<std::string, std::string_view, std::less<>> fields_;
    std::string where_;
};

// ROS 1 time: u32 seconds, u32 nanoseconds.
int64_t TimeNs(uint64_t packed) {
    const auto sec = static_cast<int64_t>(packed & 0xffffffffu);
    const auto nsec = static_cast<int64_t>(packed >> 32);
    return sec * 1000000000 + nsec;
}

}  // namespace

namespace {

// A record read from the file: its header fields and, when asked for, its data.
struct FileRecord {
    std::vector<uint8_t> header, data;
    uint32_t data_size = 0;
    uint64_t end = 0;  // offset of the next record
};

FileRecord ReadRecord(const FileReader& file, uint64_t offset, bool with_data) {
    FileRecord r;
    std::vector<uint8_t> word;
    file.Read(offset, 4, word, "record header length");
    const auto header_size = core::LoadScalar<uint32_t>(word.data(), false);
    if (header_size > kMaxHeaderBytes) {
        Fail(At(file.name(), "record", offset),
             "header of " + std::to_string(header_size) + " bytes (damaged)");
    }
    file.Read(offset + 4, header_size, r.header, "record header");
    file.Read(offset + 4 + header_size, 4, word, "record data length");
    r.data_size = core::LoadScalar<uint32_t>(word.data(), false);
    const uint64_t data_at = offset + 8 + header_size;
    if (data_at + r.data_size > file.size()) {
        Fail(file.name(), "truncated: the record at byte " + std::to_string(offset) + " declares " +
                              std::to_string(r.data_size) + " bytes of data, the file has " +
                              std::to_string(file.size() - data_at) + " more");
    }
    if (with_data) file.Read(data_at, r.data_size, r.data, "record data");
    r.end = data_at + r.data_size;
    return r;
}

}  // namespace

Ros1Bag::Ros1Bag(const std::filesystem::path& path) : file_(path) {
    const std::string& name = file_.name();
    info_.path = path;
    info_.format = "ROS 1 bag 2.0";
    info_.bytes = file_.size();
    std::vector<uint8_t> magic;
    if (file_.size() < kMagic.size()) Fail(name, "not a ROS 1 bag (too short for its first line)");
    file_.Read(0, kMagic.size(), magic, "first line");
    const std::string_view first(reinterpret_cast<const char*>(magic.data()), magic.size());
    if (first != kMagic) {
        if (first.substr(0, 9) == "#ROSBAG V") {
            const size_t eol = first.find('\n');
            Fail(name, "ROS bag version " + std::string(first.substr(9, eol - 9)) +
                           ", strata reads version 2.0 (rosbag fix converts older bags)");
        }
        Fail(name, "not a ROS 1 bag: it does not start with \"#ROSBAG V2.0\"");
    }
    const FileRecord header = ReadRecord(file_, kMagic.size(), false);
    const std::string where = At(name, "bag header", kMagic.size());
    const Fields fields(header.header.data(), header.header.size(), where);
    if (fields.Op() != kOpBagHeader) Fail(where, "the first record is not the bag header");
    const auto index_pos = fields.Scalar<uint64_t>("index_pos");
    const auto conn_count = fields.Scalar<uint32_t>("conn_count");
    const auto chunk_count = fields.Scalar<uint32_t>("chunk_count");
    first_record_ = header.end;
    if (index_pos == 0) {
        ScanRecords();
    } else {
        if (index_pos < first_record_ || index_pos >= file_.size()) {
            Fail(name, "truncated or damaged: the index is at byte " + std::to_string(index_pos) +
                           ", the file has " + std::to_string(file_.size()) + " bytes");
        }
        ReadIndex(index_pos, conn_count, chunk_count);
    }
    topics_.Finish(info_);
}

Ros1Bag::~Ros1Bag() = default;

void Ros1Bag::AddConnection(const uint8_t* header, size_t header_size, const uint8_t* data,
                            size_t data_size, const std::string& where) {
    const Fields h(header, header_size, where);
    const auto id = h.Scalar<uint32_t>("conn");
    const std::string topic = h.String("topic");
    const Fields d(data, data_size, where);
    topics_.Add(id, topic, d.String("type"), Encoding::kRos1, where);
}

void Ros1Bag::ReadIndex(uint64_t index_pos, uint32_t conn_count, uint32_t chunk_count) {
    const std::string& name = file_.name();
    uint64_t offset = index_pos;
    uint32_t connections = 0;
    std::map<uint32_t, uint64_t> counts;
    std::set<std::string> compressions;
    while (offset < file_.size()) {
        const FileRecord r = ReadRecord(file_, offset, true);
        const std::string where = At(name, "index record", offset);
        const Fields h(r.header.data(), r.header.size(), where);
        const uint8_t op = h.Op();
        if (op == kOpConnection) {
            AddConnection(r.header.data(), r.header.size(), r.data.data(), r.data.size(), where);
            ++connections;
        } else if (op == kOpChunkInfo) {
            Chunk chunk;
            chunk.position = h.Scalar<uint64_t>("chunk_pos");
            const int64_t start = TimeNs(h.Scalar<uint64_t>("start_time"));
            const int64_t end = TimeNs(h.Scalar<uint64_t>("end_time"));
            const auto n = h.Scalar<uint32_t>("count");
            core::ByteCursor in(r.data.data(), r.data.size(), where);
            if (static_cast<uint64_t>(n) * 8 != r.data.size()) {
                Fail(where, "chunk info for " + std::to_string(n) + " connections holds " +
                                std::to_string(r.data.size()) + " bytes");
            }
            for (uint32_t i = 0; i < n; ++i) {
                const auto conn = in.Read<uint32_t>("connection");
                counts[conn] += in.Read<uint32_t>("message count");
                chunk.connections.insert(conn);
            }
            if (chunk.position < first_record_ || chunk.position >= index_pos) {
                Fail(where, "chunk position " + std::to_string(chunk.position) +
                                " lies outside the chunks");
            }
            const FileRecord c = ReadRecord(file_, chunk.position, false);
            const Fields ch(c.header.data(), c.header.size(), At(name, "chunk", chunk.position));
            if (ch.Op() != kOpChunk) {
                Fail(At(name, "chunk", chunk.position), "the index points at no chunk");
            }
            compressions.insert(ch.String("compression"));
            if (info_.chunks == 0 || start < info_.start_ns) info_.start_ns = start;
            if (info_.chunks == 0 || end > info_.end_ns) info_.end_ns = end;
            ++info_.chunks;
            chunks_.push_back(std::move(chunk));
        } else {
            Fail(where, "unexpected record (op " + std::to_string(op) + ") in the index");
        }
        offset = r.end;
    }
    if (connections != conn_count || chunks_.size() != chunk_count) {
        Fail(name, "the index holds " + std::to_string(connections) + " connections and " +
                       std::to_string(chunks_.size()) + " chunks, the bag header declares " +
                       std::to_string(conn_count) + " and " + std::to_string(chunk_count));
    }
    for (const auto& [conn, n] : counts) {
        if (!topics_.Has(conn)) {
            Fail(name, "the index counts messages of connection " + std::to_string(conn) +
                           ", which it does not declare");
        }
        topics_.Count(conn, n);
    }
    std::sort(chunks_.begin(), chunks_.end(),
              [](const Chunk& a, const Chunk& b) { return a.position < b.position; });
    for (const std::string& c : compressions) {
        info_.compression += (info_.compression.empty() ? "" : ", ") + c;
    }
}

void Ros1Bag::ScanRecords() {
    const std::string& name = file_.name();
    info_.indexed = false;
    std::set<std::string> compressions;
    uint64_t offset = first_record_;
    while (offset < file_.size()) {
        FileRecord r = ReadRecord(file_, offset, true);
        const std::string where = At(name, "record", offset);
        const Fields h(r.header.data(), r.header.size(), where);
        const uint8_t op = h.Op();
        if (op == kOpChunk) {
            compressions.insert(h.String("compression"));
            Chunk chunk;
            chunk.position = offset;
            const auto on_message = [&](uint32_t conn, int64_t t, const uint8_t*, size_t,
                                        uint64_t) {
                if (!topics_.Has(conn)) {
                    Fail(At(name, "chunk", offset), "a message of connection " +
                                                        std::to_string(conn) +
                                                        " before its connection record");
                }
                topics_.Count(conn, 1);
                if (info_.start_ns == 0 || t < info_.start_ns) info_.start_ns = t;
                info_.end_ns = std::max(info_.end_ns, t);
                chunk.connections.insert(conn);
            };
            const auto on_connection = [&](const uint8_t* header, size_t header_size,
                                           const uint8_t* data, size_t data_size,
                                           const std::string& at) {
                AddConnection(header, header_size, data, data_size, at);
            };
            VisitChunk(Uncompress(r.header, std::move(r.data), offset), offset, on_message,
                       on_connection);
            ++info_.chunks;
            chunks_.push_back(std::move(chunk));
        } else if (op == kOpConnection) {
            AddConnection(r.header.data(), r.header.size(), r.data.data(), r.data.size(), where);
        } else if (op != kOpIndex && op != kOpChunkInfo) {
            Fail(where, "unexpected record (op " + std::to_string(op) + ")");
        }
        offset = r.end;
    }
    for (const std::string& c : compressions) {
        info_.compression += (info_.compression.empty() ? "" : ", ") + c;
    }
}

std::vector<uint8_t> Ros1Bag::Uncompress(const std::vector<uint8_t>& header,
                                         std::vector<uint8_t>&& data, uint64_t offset) const {
    const std::string where = At(file_.name(), "chunk", offset);
    const Fields h(header.data(), header.size(), where);
    const std::string compression = h.String("compression");
    const auto size = h.Scalar<uint32_t>("size");
    std::vector<uint8_t> plain;
    CheckDeclaredSize(data.size(), size, where);
    if (compression == "none") {
        if (data.size() != size) {
            Fail(where, "uncompressed chunk of " + std::to_string(data.size()) +
                            " bytes declares " + std::to_string(size));
        }
        return std::move(data);
    }
    if (compression == "bz2") {
        DecompressBz2(data.data(), data.size(), size, plain, where);
    } else if (compression == "lz4") {
        DecompressLz4Frame(data.data(), data.size(), size, plain, where);
    } else {
        Fail(where, "unknown compression '" + compression + "' (strata reads none, bz2 and lz4)");
    }
    return plain;
}

void Ros1Bag::VisitChunk(const std::vector<uint8_t>& records, uint64_t offset,
                         const OnMessage& on_message, const OnConnection& on_connection) const {
    const std::string where = At(file_.name(), "chunk", offset);
    core::ByteCursor in(records.data(), records.size(), where);
    while (in.remaining() > 0) {
        const size_t at = in.position();
        const auto header_size = in.Read<uint32_t>("record header length");
        const uint8_t* record_header = in.Take(header_size, "record header");
        const auto data_size = in.Read<uint32_t>("record data length");
        const uint8_t* record_data = in.Take(data_size, "record data");
        const std::string record_where = where + ", record at byte " + std::to_string(at);
        const Fields f(record_header, header_size, record_where);
        const uint8_t op = f.Op();
        if (op == kOpMessage) {
            on_message(f.Scalar<uint32_t>("conn"), TimeNs(f.Scalar<uint64_t>("time")), record_data,
                       data_size, at);
        } else if (op == kOpConnection) {
            if (on_connection) {
                on_connection(record_header, header_size, record_data, data_size, record_where);
            }
        } else {
            Fail(record_where, "unexpected record (op " + std::to_string(op) + ") in a chunk");
        }
    }
}

void Ros1Bag::Read(const std::vector<std::string>& topics, const Visitor& visit) const {
    const std::set<uint32_t> wanted = topics_.Streams(topics, info_);
    for (const Chunk& chunk : chunks_) {
        const bool any = std::any_of(chunk.connections.begin(), chunk.connections.end(),
                                     [&](uint32_t c) { return wanted.count(c) != 0; });
        if (!any) continue;
        FileRecord r = ReadRecord(file_, chunk.position, true);
        // Connection records in chunks repeat the index's (or were read when the bag was opened).
        VisitChunk(
            Uncompress(r.header, std::move(r.data), chunk.position), chunk.position,
            [&](uint32_t conn, int64_t t, const uint8_t* data, size_t size, uint64_t record) {
                if (wanted.count(conn) == 0) return;
                visit(Message{topics_.TopicOf(conn, info_), t, data, size,
                              MessageLocation{chunk.position, record}});
            },
            {});
    }
}

void Ros1Bag::ReadMessage(const MessageLocation& location, const Visitor& visit) const {
    const auto chunk = std::find_if(chunks_.begin(), chunks_.end(),
                                    [&](const Chunk& c) { return c.position == location.chunk; });
    const std::string where = At(file_.name(), "chunk", location.chunk);
    if (chunk == chunks_.end()) Fail(where, "no chunk starts there");
    const std::lock_guard<std::mutex> lock(cache_mutex_);
    if (cached_chunk_ != location.chunk || cached_.empty()) {
        FileRecord r = ReadRecord(file_, location.chunk, true);
        cached_ = Uncompress(r.header, std::move(r.data), location.chunk);
        cached_chunk_ = location.chunk;
    }
    core::ByteCursor in(cached_.data(), cached_.size(), where);
    in.Seek(location.record, "the message");
    const auto header_size = in.Read<uint32_t>("record header length");
    const uint8_t* header = in.Take(header_size, "record header");
    const auto data_size = in.Read<uint32_t>("record data length");
    const uint8_t* data = in.Take(data_size, "record data");
    const Fields f(header, header_size, where);
    if (f.Op() != kOpMessage) Fail(where, "no message at " + std::to_string(location.record));
    const Topic* topic = topics_.TopicOf(f.Scalar<uint32_t>("conn"), info_);
    if (topic == nullptr) Fail(where, "a message of an undeclared connection");
    visit(Message{topic, TimeNs(f.Scalar<uint64_t>("time")), data, data_size, location});
}

}  // namespace strata::recordings::detail
