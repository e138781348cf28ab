#pragma once
// Private to the store: what a session writer keeps of its session beside the fused map, and the
// layer grids that become of it in each tile (docs/store.md, "Session layers").

#include <map>
#include <set>
#include <string>

#include "strata/core/GridTypes.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store::detail {

/// One session's own record over some tiles: its log-odds (the session's scans alone, integrated
/// with the map's rule), every voxel its rays crossed (a miss) and every voxel its points ended in
/// (a hit), at any scan.
struct SessionGrids {
    openvdb::FloatGrid::Ptr logodds;
    openvdb::MaskGrid::Ptr crossed;
    openvdb::MaskGrid::Ptr hit;

    /// Empty grids in `transform`.
    [[nodiscard]] static SessionGrids Create(const openvdb::math::Transform& transform);
    /// From the grids of Grids() (a file an eviction wrote); `file` names it in errors.
    [[nodiscard]] static SessionGrids FromGrids(const openvdb::GridPtrVec& grids,
                                                const std::string& file);

    /// A scan's update: log-odds hit and miss, and the voxels it crossed (ScanUpdate::crossed,
    /// which must be there) and ended in.
    void Apply(const integration::ScanUpdate& update, const integration::IntegrationConfig& rule);
    /// Moves the leaves in `keys` out, one SessionGrids per key (every key gets one).
    [[nodiscard]] std::map<TileKey, SessionGrids> StealTiles(const MapSettings& settings,
                                                             const std::set<TileKey>& keys);
    /// Moves every leaf of `tile` in (their leaves must not overlap).
    void Merge(SessionGrids& tile);
    /// Drops branches emptied by StealTiles.
    void PruneInactive();
    [[nodiscard]] size_t MemUsage() const;
    [[nodiscard]] bool empty() const { return logodds->activeVoxelCount() == 0; }
    /// The three grids, named, for a file that is read back by FromGrids.
    [[nodiscard]] openvdb::GridPtrVec Grids() const;
};

/// The layer file's grids of session `session` in one tile (store::SessionLayer): occupied and
/// free from the log-odds, crossed = crossed and occupied, grazed = free and not crossed,
/// hit = hit and free.
[[nodiscard]] openvdb::GridPtrVec LayerGrids(int64_t session, const SessionGrids& tile);

}  // namespace strata::store::detail
