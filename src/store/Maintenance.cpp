// check, gc and the history policy: verifying every referenced file, removing unreferenced ones,
// dropping old history in one transaction.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <functional>
#include <mutex>
#include <regex>
#include <set>

#include "Catalog.hpp"
#include "MapStoreImpl.hpp"
#include "TileFile.hpp"
#include "strata/core/Error.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store {
namespace {

namespace fs = std::filesystem;
using detail::Statement;

// Every file a kept snapshot can reach, with how to verify it.
struct Referenced {
    std::string file;
    std::function<void()> verify;
};

std::vector<Referenced> ReferencedFiles(const MapStore& store, const detail::Database& db) {
    std::vector<Referenced> out;
    for (const TileVersion& v : detail::ReadAllTileVersions(db)) {
        if (!v.file.empty()) out.push_back({v.file, [&store, v] { (void)store.ReadFused(v); }});
    }
    for (const LayerFile& l : detail::ReadAllLayers(db)) {
        out.push_back({l.file, [&store, l] { (void)store.ReadLayer(l); }});
    }
    for (const ProductFile& p : detail::ReadAllProducts(db)) {
        out.push_back({p.file, [&store, p] { (void)store.ReadProduct(p); }});
    }
    return out;
}

// Files under tiles/ outside `referenced`, sorted.
std::vector<std::string> Unreferenced(const fs::path& dir,
                                      const std::set<std::string>& referenced) {
    std::vector<std::string> out;
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(dir / "tiles", ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        std::error_code ignored;
        if (!it->is_regular_file(ignored)) continue;
        const std::string rel = fs::relative(it->path(), dir).generic_string();
        if (!referenced.count(rel)) out.push_back(rel);
    }
    std::sort(out.begin(), out.end());
    return out;
}

// Removes files (relative to `dir`) and the tile folders they leave empty.
void RemoveFiles(const fs::path& dir, const std::vector<std::string>& files, GcReport& report) {
    for (const std::string& rel : files) {
        std::error_code ec;
        const auto size = fs::file_size(dir / rel, ec);
        if (fs::remove(dir / rel, ec)) {
            report.removed.push_back(rel);
            report.bytes += ec ? 0 : size;
        }
    }
    std::error_code ec;
    for (auto it = fs::directory_iterator(dir / "tiles", ec); !ec && it != fs::directory_iterator();
         it.increment(ec)) {
        std::error_code ignored;
        if (it->is_directory(ignored) && fs::is_empty(it->path(), ignored)) {
            fs::remove(it->path(), ignored);
        }
    }
}

// The files of the rows a query selects (column 0).
std::vector<std::string> Files(const detail::Database& db, const char* sql, int64_t commit) {
    Statement q(db, sql);
    q.Bind(1, commit);
    std::vector<std::string> out;
    while (q.Step()) {
        if (!q.IsNull(0)) out.push_back(q.Text(0));
    }
    return out;
}

// The oldest commit the policy keeps the snapshot of.
int64_t KeptFrom(const std::vector<std::pair<int64_t, std::string>>& commits,
                 const HistoryPolicy& policy) {
    if (commits.empty()) return 0;
    if (policy.keep_last > 0) {
        const size_t n = static_cast<size_t>(policy.keep_last);
        return commits[commits.size() > n ? commits.size() - n : 0].first;
    }
    // The snapshot current at the date (the newest commit not after it) and every later one.
    int64_t kept = commits.front().first;
    for (const auto& [id, time] : commits) {
        if (time <= policy.keep_since_utc) kept = id;
    }
    return kept;
}

}  // namespace

void HistoryPolicy::Validate() const {
    if ((keep_last > 0) == !keep_since_utc.empty()) {
        throw InvalidArgumentError(
            "give exactly one of --keep-last N (N >= 1) and --keep-since "
            "DATE");
    }
    static const std::regex kDate(R"(\d{4}-\d{2}-\d{2}(T\d{2}:\d{2}(:\d{2}(\.\d+)?)?Z?)?)");
    if (!keep_since_utc.empty() && !std::regex_match(keep_since_utc, kDate)) {
        throw InvalidArgumentError("--keep-since '" + keep_since_utc +
                                   "' is not an ISO 8601 UTC date (2024-06-01 or "
                                   "2024-06-01T12:00:00Z)");
    }
}

CheckReport MapStore::Check() const {
    CheckReport report;
    {
        Statement q(*impl_->db, "PRAGMA quick_check");
        while (q.Step()) {
            if (q.Text(0) != "ok") report.problems.push_back({"catalog.sqlite", q.Text(0)});
        }
    }
    const std::vector<Referenced> files = ReferencedFiles(*this, *impl_->db);
    std::set<std::string> referenced;
    for (const Referenced& r : files) referenced.insert(r.file);
    report.files = files.size();
    std::mutex mutex;
    tbb::parallel_for(size_t{0}, files.size(), [&](size_t i) {
        try {
            files[i].verify();
        } catch (const std::exception& e) {
            const std::lock_guard<std::mutex> lock(mutex);
            report.problems.push_back({files[i].file, e.what()});
        }
    });
    std::sort(report.problems.begin(), report.problems.end(),
              [](const CheckProblem& a, const CheckProblem& b) { return a.file < b.file; });
    report.unreferenced = Unreferenced(impl_->dir, referenced);
    return report;
}

GcReport MapStore::CollectGarbage() {
    impl_->RequireWriter("gc");
    std::set<std::string> referenced;
    for (const Referenced& r : ReferencedFiles(*this, *impl_->db)) referenced.insert(r.file);
    GcReport report;
    RemoveFiles(impl_->dir, Unreferenced(impl_->dir, referenced), report);
    report.history_start = HistoryStart();
    return report;
}

GcReport MapStore::DropHistory(const HistoryPolicy& policy) {
    impl_->RequireWriter("gc");
    policy.Validate();
    const detail::Database& db = *impl_->db;
    std::vector<std::string> dropped;
    int64_t kept = 0;
    {
        // One transaction: a crash leaves the history as it was or as the policy says, and the
        // files of dropped rows are garbage until removed below (or by the next gc).
        detail::Transaction tx(db, detail::Transaction::Kind::kWrite);
        kept = std::max(KeptFrom(detail::CommitTimes(db), policy), detail::HistoryStart(db));
        // Fused versions superseded at `kept`; the newest one at `kept` stays, even an empty one.
        constexpr const char* kOldVersions =
            "FROM tile_versions AS v WHERE EXISTS (SELECT 1 FROM tile_versions w WHERE w.x = v.x "
            "AND w.y = v.y AND w.version > v.version AND w.commit_id <= ?1)";
        // Layers of sessions no kept snapshot holds (removed at or before `kept`).
        constexpr const char* kOldLayers =
            "FROM layers WHERE session_id IN (SELECT id FROM sessions WHERE removed_commit_id "
            "IS NOT NULL AND removed_commit_id <= ?1)";
        // Products of commits a newer commit of their kind had replaced by `kept`.
        constexpr const char* kOldProducts =
            "FROM products AS p WHERE p.commit_id < (SELECT MAX(c.id) FROM commits c WHERE "
            "c.kind = p.kind AND c.id <= ?1)";
        for (const char* rows : {kOldVersions, kOldLayers, kOldProducts}) {
            for (std::string& f : Files(db, (std::string("SELECT file ") + rows).c_str(), kept)) {
                dropped.push_back(std::move(f));
            }
            Statement(db, (std::string("DELETE ") + rows).c_str()).Bind(1, kept).Run();
        }
        detail::SetHistoryStart(db, kept);
        tx.Commit();
    }
    GcReport report;
    RemoveFiles(impl_->dir, dropped, report);
    report.history_start = HistoryStart();
    return report;
}

}  // namespace strata::store
