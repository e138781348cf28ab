// rosbag2's SQLite storage: each .db3 file has a `topics` table (id, name, type,
// serialization_format, ...) and a `messages` table (id, topic_id, timestamp in ns, data: the
// serialized message, CDR for ROS 2, or that compressed by zstd in compression_mode MESSAGE). A bag
// folder lists its files in metadata.yaml
// (`relative_file_paths`); they are read in that order. Files are opened read-only and
// immutable, so a bag on a read-only medium reads, and no journal is written beside it.
#include "Rosbag2Sqlite.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <set>
#include <sstream>

#include "Decompress.hpp"
#include "FileReader.hpp"
#include "strata/core/Error.hpp"

namespace strata::recordings::detail {
namespace {

constexpr uint32_t kTopicBits = 20;  // topic ids below 2^20 in each file; the file index above

// The files a bag folder's metadata.yaml lists under `relative_file_paths` (a YAML block list),
// or, without metadata.yaml, its .db3 files by name.
std::vector<std::filesystem::path> BagFiles(const std::filesystem::path& dir) {
    namespace fs = std::filesystem;
    std::vector<fs::path> files;
    const fs::path metadata = dir / "metadata.yaml";
    if (fs::exists(metadata)) {
        std::ifstream in(metadata);
        std::string line;
        bool in_list = false;
        size_t list_indent = 0;
        while (std::getline(in, line)) {
            const size_t indent = line.find_first_not_of(' ');
            if (indent == std::string::npos) continue;
            const std::string text = line.substr(indent);
            if (text.rfind("relative_file_paths:", 0) == 0) {
                in_list = true;
                list_indent = indent;
                continue;
            }
            if (!in_list) continue;
            if (text.rfind("- ", 0) == 0 && indent >= list_indent) {
                std::string name = text.substr(2);
                name.erase(name.find_last_not_of(" \r\"'") + 1);
                name.erase(0, name.find_first_not_of(" \"'"));
                files.push_back(dir / name);
            } else {
                in_list = false;
            }
        }
        if (files.empty()) Fail(metadata.string(), "no relative_file_paths listed");
        return files;
    }
    for (const auto& e : fs::directory_iterator(dir)) {
        if (e.path().extension() == ".db3") files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    if (files.empty()) {
        throw NotFoundError(dir.string() +
                            ": a folder without metadata.yaml or .db3 files (not a "
                            "rosbag2 bag)");
    }
    return files;
}

// The value of `key:` in a bag folder's metadata.yaml (the first line that has it, quotes
// dropped), or empty.
std::string MetadataField(const std::filesystem::path& metadata, const std::string& key) {
    std::ifstream in(metadata);
    for (std::string line; std::getline(in, line);) {
        const size_t at = line.find_first_not_of(' ');
        if (at == std::string::npos || line.compare(at, key.size() + 1, key + ":") != 0) continue;
        std::string value = line.substr(at + key.size() + 1);
        value.erase(value.find_last_not_of(" \r\"'") + 1);
        value.erase(0, value.find_first_not_of(" \"'"));
        return value;
    }
    return {};
}

// rosbag2's compression as the folder's metadata.yaml declares it: none, or zstd on each message
// (read here); a whole file compressed (FILE mode, `bag_0.db3.zstd`) cannot be opened by SQLite
// and is refused with what to do.
std::string Compression(const std::filesystem::path& dir) {
    const std::filesystem::path metadata = dir / "metadata.yaml";
    if (!std::filesystem::exists(metadata)) return "none";
    std::string mode = MetadataField(metadata, "compression_mode");
    const std::string format = MetadataField(metadata, "compression_format");
    std::transform(mode.begin(), mode.end(), mode.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    if (mode.empty() || mode == "NONE") return "none";
    if (mode == "FILE") {
        Fail(metadata.string(), "its files are compressed whole (compression_mode FILE, " + format +
                                    "): decompress each (zstd -d FILE.db3.zstd) and list the "
                                    ".db3 files in relative_file_paths");
    }
    if (mode != "MESSAGE" || format != "zstd") {
        Fail(metadata.string(), "compression " + format + " in mode " + mode +
                                    " (strata reads zstd on each message, or none)");
    }
    return "zstd (each message)";
}

// A prepared statement, finalized when it goes.
class Statement {
public:
    Statement(sqlite3* db, const std::string& sql, const std::string& file) : file_(file) {
        if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK) {
            Fail(file_, std::string("not a rosbag2 database: ") + sqlite3_errmsg(db));
        }
    }
    ~Statement() { sqlite3_finalize(stmt_); }
    Statement(const Statement&) = delete;
    Statement& operator=(const Statement&) = delete;

    /// @brief The next row; false at the end. FormatError on a damaged database.
    bool Step() {
        const int rc = sqlite3_step(stmt_);
        if (rc == SQLITE_ROW) return true;
        if (rc == SQLITE_DONE) return false;
        Fail(file_, std::string("damaged database: ") + sqlite3_errmsg(sqlite3_db_handle(stmt_)));
    }
    [[nodiscard]] int64_t Int(int column) const { return sqlite3_column_int64(stmt_, column); }
    [[nodiscard]] std::string Text(int column) const {
        const auto* p = sqlite3_column_text(stmt_, column);
        return p == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(p));
    }
    [[nodiscard]] const uint8_t* Blob(int column, size_t* size) const {
        const void* p = sqlite3_column_blob(stmt_, column);
        *size = static_cast<size_t>(sqlite3_column_bytes(stmt_, column));
        return static_cast<const uint8_t*>(p);
    }
    void Bind(int index, int64_t value) { sqlite3_bind_int64(stmt_, index, value); }

private:
    sqlite3_stmt* stmt_ = nullptr;
    std::string file_;
};

}  // namespace

const uint8_t* Rosbag2Sqlite::Payload(const uint8_t* data, size_t* size,
                                      const std::string& file) const {
    // A CDR message begins with its encapsulation header (0x00 0x00 or 0x00 0x01), never with
    // zstd's magic, so a compressed message is known by its first bytes, declared or not.
    if (data == nullptr || !IsZstdFrame(data, *size)) return data;
    const std::string where = file + ": a zstd-compressed message";
    DecompressZstdFrame(data, *size, buffer_, where);
    *size = buffer_.size();
    return buffer_.data();
}

uint32_t Rosbag2Sqlite::Stream(size_t file, int64_t topic_id) {
    return static_cast<uint32_t>(file << kTopicBits) | static_cast<uint32_t>(topic_id);
}

Rosbag2Sqlite::Rosbag2Sqlite(const std::filesystem::path& path) {
    info_.path = path;
    info_.format = "rosbag2 SQLite";
    info_.compression = std::filesystem::is_directory(path) ? Compression(path) : "none";
    const std::vector<std::filesystem::path> paths =
        std::filesystem::is_directory(path) ? BagFiles(path) : std::vector{path};
    if (paths.size() >= (size_t{1} << (32 - kTopicBits))) Fail(path.string(), "too many files");
    bool any = false;
    for (size_t f = 0; f < paths.size(); ++f) {
        const std::string name = paths[f].string();
        const FileReader check(paths[f]);  // NotFoundError / IoError naming the file
        info_.bytes += check.size();
        Database d{name, nullptr};
        const std::string uri = "file:" + name + "?immutable=1";
        if (sqlite3_open_v2(uri.c_str(), &d.db, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr) !=
            SQLITE_OK) {
            const std::string message = d.db != nullptr ? sqlite3_errmsg(d.db) : "out of memory";
            sqlite3_close(d.db);
            Fail(name, "cannot open as SQLite: " + message);
        }
        files_.push_back(d);
        Statement topics(d.db, "SELECT id, name, type, serialization_format FROM topics", name);
        while (topics.Step()) {
            const int64_t id = topics.Int(0);
            if (id < 0 || id >= (int64_t{1} << kTopicBits))
                Fail(name, "topic id " + std::to_string(id));
            topics_.Add(Stream(f, id), topics.Text(1), topics.Text(2), EncodingOf(topics.Text(3)),
                        name);
        }
        Statement counts(d.db,
                         "SELECT topic_id, COUNT(*), MIN(timestamp), MAX(timestamp) FROM messages "
                         "GROUP BY topic_id",
                         name);
        while (counts.Step()) {
            const uint32_t stream = Stream(f, counts.Int(0));
            if (!topics_.Has(stream)) {
                Fail(name, "messages of topic id " + std::to_string(counts.Int(0)) +
                               ", which the topics table does not list");
            }
            topics_.Count(stream, static_cast<uint64_t>(counts.Int(1)));
            if (!any || counts.Int(2) < info_.start_ns) info_.start_ns = counts.Int(2);
            if (!any || counts.Int(3) > info_.end_ns) info_.end_ns = counts.Int(3);
            any = true;
        }
    }
    info_.chunks = files_.size();
    topics_.Finish(info_);
}

Rosbag2Sqlite::~Rosbag2Sqlite() {
    for (const Database& d : files_) sqlite3_close(d.db);
}

void Rosbag2Sqlite::Read(const std::vector<std::string>& topics, const Visitor& visit) const {
    const std::set<uint32_t> wanted = topics_.Streams(topics, info_);
    const std::lock_guard<std::mutex> lock(mutex_);
    for (size_t f = 0; f < files_.size(); ++f) {
        Statement rows(files_[f].db,
                       "SELECT topic_id, timestamp, data, id FROM messages ORDER BY timestamp, id",
                       files_[f].name);
        while (rows.Step()) {
            const uint32_t stream = Stream(f, rows.Int(0));
            if (wanted.count(stream) == 0) continue;
            size_t size = 0;
            const uint8_t* data = Payload(rows.Blob(2, &size), &size, files_[f].name);
            visit(Message{topics_.TopicOf(stream, info_), rows.Int(1), data, size,
                          MessageLocation{f, static_cast<uint64_t>(rows.Int(3))}});
        }
    }
}

void Rosbag2Sqlite::ReadMessage(const MessageLocation& location, const Visitor& visit) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (location.chunk >= files_.size()) Fail(info_.path.string(), "no such file in the bag");
    const Database& d = files_[location.chunk];
    Statement row(d.db, "SELECT topic_id, timestamp, data FROM messages WHERE id = ?", d.name);
    row.Bind(1, static_cast<int64_t>(location.record));
    if (!row.Step()) Fail(d.name, "no message " + std::to_string(location.record));
    size_t size = 0;
    const uint8_t* data = Payload(row.Blob(2, &size), &size, d.name);
    const Topic* topic = topics_.TopicOf(Stream(location.chunk, row.Int(0)), info_);
    if (topic == nullptr) Fail(d.name, "a message of an undeclared topic");
    visit(Message{topic, row.Int(1), data, size, location});
}

}  // namespace strata::recordings::detail
