#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <vector>

#include "strata/registration/RegistrationConfig.hpp"
#include "strata/registration/Surface.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::registration {

/// @brief The matching surface of a map's occupied voxels inside a box, read from the tiles only
/// around the source: each level holds the cells within `cover_cells` cells of the source's
/// points (moved by the estimate it was built at), fitted from the cells two further out, and is
/// read again when the alignment moves a point out of them. A level answers exactly as
/// Surface::FromPoints of all the box's points would
/// (TileByTile.RegisterReadsTheWholeMapsPointsTileByTile), while the
/// memory follows the source's sampled points, not the map or the session.
/// @note Holds a reference to `map` (and a copy of `snapshot`). Errors of the store propagate.
class MapSurface final : public SurfaceLevels {
public:
    /// @param cover_cells cells of slack around each source point's cell before a level is read
    /// again: more reads less often (0 reads again at any move to another cell).
    /// @throw InvalidArgumentError on an invalid config or a negative `cover_cells`. Reads
    /// nothing yet.
    MapSurface(const store::MapStore& map, const store::Snapshot& snapshot,
               const Eigen::AlignedBox3d& box, const SurfaceConfig& config, int cover_cells = 1);

    /// @brief Reads the coarse levels (all but the finest) around their sources, in one pass
    /// over the tiles; the finest is read when the alignment first asks for it.
    void Prepare(const std::vector<std::vector<Eigen::Vector3d>>& sources,
                 const Eigen::Isometry3d& T) override;
    /// @brief Level `l`, read again when a point of `source` moved by `T` left its cover; the
    /// coarser levels are dropped (the alignment went past them).
    [[nodiscard]] const SurfaceLevel& Around(size_t l, const std::vector<Eigen::Vector3d>& source,
                                             const Eigen::Isometry3d& T) override;

    /// Passes over the tiles so far (one reads one level or more).
    [[nodiscard]] size_t reads() const { return reads_; }
    /// The most occupied points (inside the box) one pass fitted cells from.
    [[nodiscard]] size_t points_read() const { return points_read_; }
    /// Milliseconds spent reading and fitting levels, all passes.
    [[nodiscard]] double read_ms() const { return read_ms_; }
    /// Whether any level read so far had a planar cell.
    [[nodiscard]] bool found_surface() const { return found_surface_; }

private:
    struct Level {
        SurfaceLevel level;
        CellMask::Ptr cover;  // the cells a query may fall in
    };
    struct Want {
        size_t level;
        const std::vector<Eigen::Vector3d>* source;
    };
    [[nodiscard]] bool Covers(size_t l, const std::vector<Eigen::Vector3d>& source,
                              const Eigen::Isometry3d& T) const;
    void Read(const std::vector<Want>& wants, const Eigen::Isometry3d& T);

    const store::MapStore& map_;
    store::Snapshot snapshot_;
    Eigen::AlignedBox3d box_;
    SurfaceConfig config_;
    int cover_cells_;
    std::vector<std::unique_ptr<Level>> levels_;
    size_t reads_ = 0;
    size_t points_read_ = 0;
    double read_ms_ = 0.0;
    bool found_surface_ = false;
};

}  // namespace strata::registration
