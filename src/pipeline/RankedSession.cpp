#include "strata/pipeline/RankedSession.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "strata/core/Error.hpp"
#include "strata/integration/UpdateParts.hpp"
#include "strata/pipeline/Sessions.hpp"

namespace strata::pipeline {
namespace {

using nlohmann::json;

// Adds the wall time of its scope to `total`.
class Timed {
public:
    explicit Timed(double& total) : total_(total), start_(std::chrono::steady_clock::now()) {}
    ~Timed() {
        total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }
    Timed(const Timed&) = delete;
    Timed& operator=(const Timed&) = delete;

private:
    double& total_;
    std::chrono::steady_clock::time_point start_;
};

// The kinds of strata::Error by a one-letter tag, so that a rank's failure is rethrown as the
// same kind on the others (the CLI maps kinds to exit codes).
char KindOf(const std::exception& e) {
    if (dynamic_cast<const InvalidArgumentError*>(&e)) return 'A';
    if (dynamic_cast<const FormatError*>(&e)) return 'F';
    if (dynamic_cast<const NotFoundError*>(&e)) return 'N';
    if (dynamic_cast<const MapLockedError*>(&e)) return 'L';
    if (dynamic_cast<const RefusedError*>(&e)) return 'R';
    if (dynamic_cast<const IoError*>(&e)) return 'I';
    return 'E';
}

[[noreturn]] void ThrowKind(char kind, const std::string& what) {
    switch (kind) {
        case 'A':
            throw InvalidArgumentError(what);
        case 'F':
            throw FormatError(what);
        case 'N':
            throw NotFoundError(what);
        case 'L':
            throw MapLockedError(what);
        case 'R':
            throw RefusedError(what);
        case 'I':
            throw IoError(what);
        default:
            throw Error(what);
    }
}

// Length-prefixed pieces of one message.
void AppendPiece(std::string& message, const std::string& piece) {
    const uint64_t n = piece.size();
    message.append(reinterpret_cast<const char*>(&n), sizeof(n));
    message += piece;
}

std::string_view NextPiece(const std::string& message, size_t& at, const std::string& what) {
    uint64_t n = 0;
    if (message.size() - at < sizeof(n)) throw FormatError(what + ": message cut short");
    std::copy_n(message.data() + at, sizeof(n), reinterpret_cast<char*>(&n));
    at += sizeof(n);
    if (message.size() - at < n) throw FormatError(what + ": message cut short");
    const std::string_view piece(message.data() + at, n);
    at += n;
    return piece;
}

json RecordJson(const store::ScanRecord& r) {
    std::vector<double> pose(r.pose.matrix().data(), r.pose.matrix().data() + 16);
    return {{"time_s", r.time_s}, {"pose", pose}, {"points", r.points}, {"source", r.source}};
}

store::ScanRecord RecordFrom(const json& j) {
    store::ScanRecord r;
    r.time_s = j.at("time_s").get<double>();
    const auto pose = j.at("pose").get<std::vector<double>>();
    if (pose.size() != 16) throw FormatError("a scan record without its 16 pose values");
    std::copy(pose.begin(), pose.end(), r.pose.matrix().data());
    r.points = j.at("points").get<size_t>();
    r.source = j.at("source").get<std::string>();
    return r;
}

json FileJson(const store::FileRef& f, const store::TileKey& key) {
    return {
        {"file", f.file}, {"bytes", f.bytes}, {"checksum", f.checksum}, {"x", key.x}, {"y", key.y}};
}

template <typename T>
T FileFrom(const json& j) {
    T f;
    f.file = j.at("file").get<std::string>();
    f.bytes = j.at("bytes").get<uint64_t>();
    f.checksum = j.at("checksum").get<uint64_t>();
    f.key = {j.at("x").get<int32_t>(), j.at("y").get<int32_t>()};
    return f;
}

std::string FilesText(const store::SessionFiles& files) {
    json j = {{"versions", json::array()}, {"layers", json::array()}};
    for (const auto& v : files.versions) {
        j["versions"].push_back(FileJson(v, v.key));
        j["versions"].back()["version"] = v.version;
    }
    for (const auto& l : files.layers) {
        j["layers"].push_back(FileJson(l, l.key));
        j["layers"].back()["session"] = l.session;
    }
    const store::WriterStats& s = files.stats;
    j["stats"] = {s.tiles_loaded,   s.tiles_evicted, s.tiles_written,
                  s.layers_written, s.bytes_written, s.peak_memory_bytes};
    return j.dump();
}

store::SessionFiles FilesFrom(const std::string& text) {
    const json j = json::parse(text);
    store::SessionFiles files;
    for (const json& v : j.at("versions")) {
        files.versions.push_back(FileFrom<store::TileVersion>(v));
        files.versions.back().version = v.at("version").get<int64_t>();
    }
    for (const json& l : j.at("layers")) {
        files.layers.push_back(FileFrom<store::LayerFile>(l));
        files.layers.back().session = l.at("session").get<int64_t>();
    }
    const auto s = j.at("stats").get<std::vector<uint64_t>>();
    if (s.size() != 6) throw FormatError("a rank's session files without their 6 counts");
    store::WriterStats& stats = files.stats;  // the timings stay with the rank that measured them
    stats.tiles_loaded = s[0];
    stats.tiles_evicted = s[1];
    stats.tiles_written = s[2];
    stats.layers_written = s[3];
    stats.bytes_written = s[4];
    stats.peak_memory_bytes = s[5];
    return files;
}

void AddStats(store::WriterStats& sum, const store::WriterStats& s) {
    sum.tiles_loaded += s.tiles_loaded;
    sum.tiles_evicted += s.tiles_evicted;
    sum.tiles_written += s.tiles_written;
    sum.layers_written += s.layers_written;
    sum.bytes_written += s.bytes_written;
    sum.peak_memory_bytes = std::max(sum.peak_memory_bytes, s.peak_memory_bytes);
}

}  // namespace

int TileOwner(const store::TileKey& key, int ranks) {
    // Diagonals: along a row or a column of tiles the owners cycle through every rank, so the
    // tiles in a scan's range are shared out evenly in every round, not only over the map.
    const int64_t n = std::max(1, ranks);
    const int64_t d = (int64_t{key.x} + int64_t{key.y}) % n;
    return static_cast<int>(d < 0 ? d + n : d);
}

void OnEveryRank(const Ranks& ranks, const std::function<void()>& step) {
    std::exception_ptr mine;
    std::string failure;  // tag + message
    try {
        step();
    } catch (const std::exception& e) {
        mine = std::current_exception();
        failure = std::string(1, KindOf(e)) + e.what();
    } catch (...) {
        mine = std::current_exception();
        failure = "Eunknown error";
    }
    if (ranks.AllOk(!mine)) return;
    // The lowest failing rank's error, for every rank; a failing rank rethrows its own.
    const std::vector<std::string> all = ranks.Gather(failure);
    std::string first;
    for (size_t r = 0; r < all.size() && first.empty(); ++r) {
        if (!all[r].empty()) first = std::to_string(r) + ' ' + all[r];
    }
    first = ranks.Broadcast(first);
    if (mine) std::rethrow_exception(mine);
    const size_t space = first.find(' ');
    ThrowKind(first.at(space + 1),
              "rank " + first.substr(0, space) + ": " + first.substr(space + 2));
}

store::MapStore OpenOnRanks(const std::filesystem::path& dir, const Ranks& ranks,
                            const std::function<store::MapStore()>& open_root) {
    std::optional<store::MapStore> map;
    OnEveryRank(ranks, [&] {
        if (ranks.root()) map.emplace(open_root());
    });
    OnEveryRank(ranks, [&] {
        if (!ranks.root()) map.emplace(store::MapStore::Open(dir, store::MapStore::Access::kRead));
    });
    return std::move(*map);
}

RankedSessionResult IntegrateOnRanks(store::MapStore& map, size_t scans,
                                     const std::function<core::Scan(size_t)>& read,
                                     const integration::IntegrationConfig& config,
                                     store::SessionOptions options, const Ranks& ranks,
                                     const std::function<void(size_t)>& progress,
                                     size_t scans_per_block) {
    const int n = ranks.size();
    const int me = ranks.rank();
    if (n > 1)
        options.owns = [n, me](const store::TileKey& key) { return TileOwner(key, n) == me; };
    // The committer's writer names the session; the others write their tiles for it.
    std::unique_ptr<store::SessionWriter> writer;
    OnEveryRank(ranks, [&] {
        if (ranks.root()) writer = std::make_unique<store::SessionWriter>(map, config, options);
    });
    options.worker_of_session =
        std::stoll(ranks.Broadcast(ranks.root() ? std::to_string(writer->session_id()) : ""));
    OnEveryRank(ranks, [&] {
        if (!ranks.root()) writer = std::make_unique<store::SessionWriter>(map, config, options);
    });

    RankedSessionResult::Seconds seconds;
    // On several ranks, scans go in rounds: rank r casts the r-th block of up to
    // `scans_per_block` consecutive scans of a round and cuts each update by tile owner; every
    // rank then applies the round's parts in its tiles in scan order. Ranks wait for each other
    // once per block rather than once per scan, whose costs vary. Rank 0 also gets each scan's
    // record.
    if (scans_per_block == 0) throw InvalidArgumentError("scans per block must be at least 1");
    const size_t block = n == 1 ? 1 : scans_per_block;
    const size_t per_round = block * static_cast<size_t>(n);
    for (size_t first = 0; first < scans; first += per_round) {
        const size_t end = std::min(scans, first + per_round);
        const auto begin_of = [&](int r) {
            return std::min(end, first + static_cast<size_t>(r) * block);
        };
        if (n == 1) {
            const Timed timed(seconds.cast);
            OnEveryRank(ranks, [&] { (void)writer->Integrate(read(first)); });
        } else {
            std::vector<std::string> out(static_cast<size_t>(n));
            OnEveryRank(ranks, [&] {
                const Timed timed(seconds.cast);
                for (size_t i = begin_of(me); i < begin_of(me + 1); ++i) {
                    const core::Scan scan = read(i);
                    const integration::ScanUpdate update = writer->Compute(scan);
                    for (int d = 0; d < n; ++d) {
                        std::string& m = out[static_cast<size_t>(d)];
                        AppendPiece(
                            m, integration::EncodeUpdate(update, [&](const openvdb::Coord& leaf) {
                                return TileOwner(map.settings().TileOf(leaf), n) == d;
                            }));
                        if (d == 0) {
                            AppendPiece(
                                m, RecordJson(store::SessionWriter::RecordOf(scan, update)).dump());
                        }
                    }
                }
            });
            std::vector<std::string> in;
            {
                const Timed timed(seconds.exchange);
                in = ranks.Exchange(out);
            }
            OnEveryRank(ranks, [&] {
                const Timed timed(seconds.apply);
                for (int r = 0; r < n; ++r) {
                    size_t at = 0;
                    for (size_t i = begin_of(r); i < begin_of(r + 1); ++i) {
                        const std::string what =
                            "rank " + std::to_string(r) + "'s update of scan " + std::to_string(i);
                        const std::string& message = in[static_cast<size_t>(r)];
                        writer->Apply(
                            integration::DecodeUpdate(NextPiece(message, at, what), what));
                        if (ranks.root()) {
                            writer->AddScan(RecordFrom(json::parse(NextPiece(message, at, what))));
                        }
                    }
                }
            });
        }
        if (ranks.root() && progress) progress(end);
    }

    // Every worker's files synced and handed to rank 0, which commits them all at once.
    const auto commit_start = std::chrono::steady_clock::now();
    // Rank 0 writes its own files meanwhile: the commit then only records them.
    std::string files;
    OnEveryRank(ranks, [&] {
        if (ranks.root()) {
            writer->WriteOwnFiles();
        } else {
            files = FilesText(writer->WriteFiles());
        }
    });
    const std::vector<std::string> all = ranks.Gather(files);
    RankedSessionResult result;
    OnEveryRank(ranks, [&] {
        if (!ranks.root()) return;
        std::vector<store::SessionFiles> workers;
        for (size_t r = 1; r < all.size(); ++r) workers.push_back(FilesFrom(all[r]));
        result.session = writer->Commit(workers);
        result.stats = writer->stats();
        for (const auto& w : workers) AddStats(result.stats, w.stats);
    });
    const json session = json::parse(
        ranks.Broadcast(ranks.root() ? json{{"session", SessionJson(result.session)},
                                            {"stats", FilesText({{}, {}, result.stats})}}
                                           .dump()
                                     : ""));
    if (!ranks.root()) {
        const json& s = session.at("session");
        result.session.id = s.at("id").get<int64_t>();
        result.session.name = s.at("name").get<std::string>();
        result.session.commit = s.at("commit").get<int64_t>();
        result.session.scans = s.at("scans").get<size_t>();
        result.session.points = s.at("points").get<size_t>();
        result.session.start_utc = s.at("start_utc").get<std::string>();
        result.session.end_utc = s.at("end_utc").get<std::string>();
        result.stats = FilesFrom(session.at("stats").get<std::string>()).stats;
    }
    seconds.commit =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - commit_start).count();
    result.seconds = seconds;
    return result;
}

}  // namespace strata::pipeline
