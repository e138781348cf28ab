// MapStore::RemoveSession: a session leaves the map in one commit, rebuilt from the layers of
// the sessions that remain.
#include <algorithm>
#include <set>
#include <stdexcept>

#include "Catalog.hpp"
#include "MapStoreImpl.hpp"
#include "TileFile.hpp"
#include "strata/integration/IntegrationConfig.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store {

namespace fs = std::filesystem;
using detail::Transaction;

int64_t MapStore::RemoveSession(int64_t session_id) {
    impl_->RequireWriter("session rm");
    const Impl& impl = *impl_;
    const Snapshot latest = Latest();
    const auto victim =
        std::find_if(latest.sessions.begin(), latest.sessions.end(),
                     [&](const SessionRecord& s) { return s.id == session_id; });
    if (victim == latest.sessions.end()) {
        throw std::runtime_error(impl.dir.string() + ": session " + std::to_string(session_id) +
                                 " is not in the map (removed already, or never added)");
    }
    // The tiles the session touched are the ones its commit wrote.
    std::set<TileKey> touched;
    for (const TileVersion& v : detail::ReadAllTileVersions(*impl.db)) {
        if (v.commit == victim->commit) touched.insert(v.key);
    }
    const integration::IntegrationConfig defaults;
    const float hit = core::LogOdds(defaults.prob_hit);
    const float miss = core::LogOdds(defaults.prob_miss);
    const float lo = core::LogOdds(defaults.clamp_min_prob);
    const float hi = core::LogOdds(defaults.clamp_max_prob);
    const auto last = detail::ReadLastVersions(*impl.db);

    std::vector<TileVersion> written;
    std::set<fs::path> dirs;
    for (const TileVersion& current : latest.tiles) {
        if (!touched.count(current.key)) continue;
        Tile tile = ReadTile(current);
        const auto layer = std::find_if(tile.layers.begin(), tile.layers.end(),
                                        [&](const SessionLayer& l) { return l.session == session_id; });
        if (layer == tile.layers.end()) continue;
        const SessionLayer removed = *layer;
        tile.layers.erase(layer);
        // Voxels the removed session never saw keep their values: it contributed nothing there.
        // Where it did, occupancy is rebuilt from the remaining layers, one vote per session in
        // session order; label, weight and hits stay only where the voxel is still occupied.
        openvdb::BoolTree seen(removed.occupied->tree());
        seen.topologyUnion(removed.free->tree());
        std::vector<openvdb::BoolGrid::ConstAccessor> occupied, free;
        for (const SessionLayer& l : tile.layers) {
            occupied.push_back(l.occupied->getConstAccessor());
            free.push_back(l.free->getConstAccessor());
        }
        auto occupancy = tile.fused.occupancy->getAccessor();
        auto label = tile.fused.label->getAccessor();
        auto weight = tile.fused.label_weight->getAccessor();
        auto endpoints = tile.fused.endpoints->getAccessor();
        for (auto it = seen.cbeginValueOn(); it; ++it) {
            const openvdb::Coord ijk = it.getCoord();
            float value = 0.0f;
            bool observed = false;
            for (size_t k = 0; k < occupied.size(); ++k) {
                if (occupied[k].isValueOn(ijk)) {
                    value = std::clamp(value + hit, lo, hi);
                    observed = true;
                } else if (free[k].isValueOn(ijk)) {
                    value = std::clamp(value + miss, lo, hi);
                    observed = true;
                }
            }
            if (observed) {
                occupancy.setValueOn(ijk, value);
            } else {
                occupancy.setValueOff(ijk, 0.0f);
            }
            if (!observed || value <= 0.0f) {
                label.setValueOff(ijk, 0);
                weight.setValueOff(ijk, 0.0f);
                endpoints.setValueOff(ijk, 0);
            }
        }
        TileVersion v;
        v.key = tile.key;
        v.version = last.at(tile.key) + 1;
        if (tile.fused.occupancy->activeVoxelCount() > 0 || !tile.layers.empty() ||
            !tile.products.empty()) {
            const detail::EncodedTile encoded = detail::EncodeTile(tile);
            v.file = impl.TileFile(tile.key, v.version);
            detail::WriteTileFile(impl.dir / v.file, encoded.bytes);
            v.bytes = encoded.bytes.size();
            v.checksum = encoded.checksum;
            dirs.insert(impl.TileDir(tile.key));
        }
        written.push_back(v);
    }
    for (const fs::path& d : dirs) detail::SyncDirectory(d);
    Transaction tx(*impl.db, Transaction::Kind::kWrite);
    const int64_t commit = detail::InsertCommit(*impl.db, "remove_session", session_id);
    for (TileVersion& v : written) {
        v.commit = commit;
        detail::InsertTileVersion(*impl.db, v);
    }
    detail::MarkSessionRemoved(*impl.db, session_id, commit);
    tx.Commit();
    return commit;
}

}  // namespace strata::store
