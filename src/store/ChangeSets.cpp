// Change sets in the catalog: results of change queries, kept so they can be listed later.
#include "Catalog.hpp"
#include "MapStoreImpl.hpp"

namespace strata::store {

int64_t MapStore::SaveChangeSet(const ChangeSetRecord& record) {
    impl_->RequireWriter("saving a change set");
    const detail::Database& db = *impl_->db;
    detail::Transaction tx(db, detail::Transaction::Kind::kWrite);
    detail::Statement q(db,
                        "INSERT INTO change_sets(commit_id, created_utc, from_side, to_side, "
                        "added_voxels, removed_voxels, unknown_voxels, objects, report) "
                        "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
    q.Bind(1, detail::LatestCommit(db))
        .Bind(2, detail::UtcNow())
        .Bind(3, record.from)
        .Bind(4, record.to)
        .Bind(5, static_cast<int64_t>(record.added_voxels))
        .Bind(6, static_cast<int64_t>(record.removed_voxels))
        .Bind(7, static_cast<int64_t>(record.unknown_voxels))
        .Bind(8, static_cast<int64_t>(record.objects))
        .Bind(9, record.report)
        .Run();
    const int64_t id = db.LastInsertId();
    tx.Commit();
    return id;
}

std::vector<ChangeSetRecord> MapStore::ChangeSets() const {
    const detail::Database& db = *impl_->db;
    std::vector<ChangeSetRecord> out;
    if (detail::CatalogVersion(db) < 2) return out;  // read-only older map: nothing was saved
    detail::Statement q(db,
                        "SELECT id, commit_id, created_utc, from_side, to_side, added_voxels, "
                        "removed_voxels, unknown_voxels, objects, report FROM change_sets "
                        "ORDER BY id");
    while (q.Step()) {
        ChangeSetRecord r;
        r.id = q.Int(0);
        r.commit = q.Int(1);
        r.created_utc = q.Text(2);
        r.from = q.Text(3);
        r.to = q.Text(4);
        r.added_voxels = static_cast<size_t>(q.Int(5));
        r.removed_voxels = static_cast<size_t>(q.Int(6));
        r.unknown_voxels = static_cast<size_t>(q.Int(7));
        r.objects = static_cast<size_t>(q.Int(8));
        r.report = q.Text(9);
        out.push_back(std::move(r));
    }
    return out;
}

}  // namespace strata::store
