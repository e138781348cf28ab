// MapStore::RemoveSession: a session leaves the map in one commit; the fused grids of the voxels
// it saw are rebuilt from the remaining sessions' layers by the integration module, with the
// rule the map was built with.

#include <algorithm>
#include <map>
#include <set>

#include "Catalog.hpp"
#include "MapStoreImpl.hpp"
#include "TileFile.hpp"
#include "TileSplit.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/ParallelFor.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store {
namespace {

namespace fs = std::filesystem;

// One vote of a session over `seen`: hit where it saw the voxel occupied, miss where free.
integration::ScanUpdate Votes(const SessionLayer& layer, const openvdb::BoolTree& seen) {
    integration::ScanUpdate u;
    u.occupied =
        std::make_shared<openvdb::MaskTree>(layer.occupied->tree(), false, openvdb::TopologyCopy());
    u.free =
        std::make_shared<openvdb::MaskTree>(layer.free->tree(), false, openvdb::TopologyCopy());
    u.occupied->topologyIntersection(seen);
    u.free->topologyIntersection(seen);
    return u;
}

// Rebuilds a tile without the removed session. Voxels it never saw keep their values: it
// contributed nothing there. Where it did, occupancy is the remaining layers' votes, one per
// session in session order (integration::ApplyOccupancyUpdate, the map's rule); label, weight,
// hits and point mean stay only where the voxel is still occupied.
void Rebuild(core::VoxelMap& tile, const SessionLayer& removed,
             const std::vector<SessionLayer>& remaining,
             const integration::IntegrationConfig& rule) {
    openvdb::BoolTree seen(removed.occupied->tree());
    seen.topologyUnion(removed.free->tree());
    openvdb::FloatGrid::Ptr votes = openvdb::FloatGrid::create(0.0f);
    for (const SessionLayer& layer : remaining) {
        integration::ApplyOccupancyUpdate(Votes(layer, seen), *votes, rule);
    }
    auto occupancy = tile.occupancy->getAccessor();
    auto rebuilt = votes->getConstAccessor();
    std::vector<openvdb::Coord> emptied;
    for (auto it = seen.cbeginValueOn(); it; ++it) {
        const openvdb::Coord ijk = it.getCoord();
        float value = 0.0f;
        if (rebuilt.probeValue(ijk, value)) {
            occupancy.setValueOn(ijk, value);
        } else {
            occupancy.setValueOff(ijk, 0.0f);
        }
        if (value <= 0.0f) emptied.push_back(ijk);
    }
    for (const auto& grid : tile.Grids()) {
        if (grid == tile.occupancy) continue;
        grid->apply<core::GridTypes>([&](auto& typed) {
            auto acc = typed.getAccessor();
            for (const openvdb::Coord& ijk : emptied) acc.setValueOff(ijk, typed.background());
        });
    }
}

}  // namespace

int64_t MapStore::RemoveSession(int64_t session_id) {
    impl_->RequireWriter("session rm");
    const Impl& impl = *impl_;
    const Snapshot latest = Latest();
    if (std::none_of(latest.sessions.begin(), latest.sessions.end(),
                     [&](const SessionRecord& s) { return s.id == session_id; })) {
        throw NotFoundError(impl.dir.string() + ": session " + std::to_string(session_id) +
                            " is not in the map (removed already, or never added)");
    }
    // The tiles the session saw are those with its layers; only they change.
    std::map<TileKey, std::vector<const LayerFile*>> by_tile;
    for (const LayerFile& l : latest.layers) by_tile[l.key].push_back(&l);
    std::vector<const TileVersion*> touched;
    for (const TileVersion& v : latest.tiles) {
        const auto it = by_tile.find(v.key);
        if (it == by_tile.end()) continue;
        if (std::any_of(it->second.begin(), it->second.end(),
                        [&](const LayerFile* l) { return l->session == session_id; })) {
            touched.push_back(&v);
        }
    }
    const auto last = detail::ReadLastVersions(*impl.db);
    std::vector<TileVersion> written(touched.size());
    std::vector<std::string> files;
    for (const TileVersion* v : touched) {
        files.push_back(detail::FusedFileName(v->key, last.at(v->key) + 1));
    }
    try {
        core::ParallelFor(touched.size(), [&](size_t i) {
            const TileVersion& current = *touched[i];
            core::VoxelMap tile = ReadFused(current);
            SessionLayer removed;
            std::vector<SessionLayer> remaining;
            for (const LayerFile* l : by_tile.at(current.key)) {
                (l->session == session_id ? removed : remaining.emplace_back()) = ReadLayer(*l);
            }
            Rebuild(tile, removed, remaining, impl.settings.integration);
            TileVersion& v = written[i];
            v.key = current.key;
            v.version = last.at(current.key) + 1;
            if (tile.occupancy->activeVoxelCount() > 0) {
                static_cast<FileRef&>(v) =
                    detail::WriteGrids(impl.dir, files[i], tile.Grids(), current.key);
            }
        });
        std::set<fs::path> dirs;
        for (const TileVersion& v : written) {
            if (!v.file.empty()) dirs.insert(impl.TileDir(v.key));
        }
        for (const fs::path& d : dirs) detail::SyncDirectory(d);
        detail::Transaction tx(*impl.db, detail::Transaction::Kind::kWrite);
        const int64_t commit = detail::InsertCommit(*impl.db, "remove_session", session_id);
        for (TileVersion& v : written) {
            v.commit = commit;
            detail::InsertTileVersion(*impl.db, v);
        }
        detail::MarkSessionRemoved(*impl.db, session_id, commit);
        tx.Commit();
        return commit;
    } catch (...) {
        impl.RemoveFiles(files);
        throw;
    }
}

}  // namespace strata::store
