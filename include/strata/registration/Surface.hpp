#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/registration/RegistrationConfig.hpp"

namespace strata::registration {

/// @brief Cells -> values >= 0, by open addressing: 16 bytes a slot, at most half of them
/// used. Compact for cells spread thinly over a wide area, where a VDB grid pays its internal
/// nodes for every 32 m it touches. Safe to read from many threads once filled.
class CellTable {
public:
    /// @brief Sets the cell's value (inserting the cell when new); `value` must be >= 0.
    void Set(const openvdb::Coord& cell, int32_t value);
    /// @brief The cell's value, or -1 when the cell is not in the table.
    [[nodiscard]] int32_t Find(const openvdb::Coord& cell) const;
    [[nodiscard]] bool Contains(const openvdb::Coord& cell) const { return Find(cell) >= 0; }
    [[nodiscard]] size_t size() const { return size_; }
    [[nodiscard]] size_t bytes() const { return slots_.size() * sizeof(Slot); }

private:
    struct Slot {
        openvdb::Coord cell;
        int32_t value = -1;  // -1: empty
    };
    [[nodiscard]] size_t SlotOf(const openvdb::Coord& cell) const;
    void Grow();

    std::vector<Slot> slots_;
    size_t size_ = 0;
};

/// @brief A set of cells spread thinly over a wide area (the cells around a source's sampled
/// points): a VDB tree of small nodes (core::SparseBoolTree), where the default's 128^3-cell
/// nodes cost 32 KB for every 32 m touched (at 0.25 m cells).
using CellMask = openvdb::Grid<core::SparseBoolTree>;

/// @brief One level of a matching surface: one point per cell of `cell_m` (the mean of the input
/// points in it) with the unit normal of its neighbourhood. Only planar cells are kept.
struct SurfaceLevel {
    double cell_m = 0.0;
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector3d> normals;
    /// Cell (floor(p / cell_m)) -> index into points.
    CellTable index;
};

/// @brief A surface to match against, coarse to fine (levels in SurfaceConfig order). Immutable
/// once built, so it may be queried from many threads.
struct Surface {
    std::vector<SurfaceLevel> levels;

    /// @brief Builds the levels from points (map frame, metres). Empty input gives empty levels.
    /// Throws InvalidArgumentError on an invalid config.
    [[nodiscard]] static Surface FromPoints(const std::vector<Eigen::Vector3d>& points,
                                            const SurfaceConfig& config);
    [[nodiscard]] bool empty() const { return levels.empty() || levels.back().points.empty(); }
};

/// @brief Where RegisterPoints finds each level of the surface it matches against: a Surface
/// holds every level whole; a MapSurface (registration/MapSurface.hpp) reads a map's tiles only
/// around the source, as the alignment moves it.
class SurfaceLevels {
public:
    virtual ~SurfaceLevels() = default;
    /// @brief Told once, before any level is asked for, the source of every level and the
    /// first estimate (a MapSurface reads them all in one pass).
    virtual void Prepare(const std::vector<std::vector<Eigen::Vector3d>>& /*sources*/,
                         const Eigen::Isometry3d& /*T*/) {}
    /// @brief Level `l` (SurfaceConfig order), answering for every point of `source` moved by
    /// `T` as the whole level would. Valid until the next call.
    [[nodiscard]] virtual const SurfaceLevel& Around(size_t l,
                                                     const std::vector<Eigen::Vector3d>& source,
                                                     const Eigen::Isometry3d& T) = 0;
};

/// @brief Where the endpoints of a map's occupied voxels (log-odds > 0) lay: the `point_mean`
/// of each voxel, its centre where unknown. Only voxels whose centre is inside `bounds` (map
/// frame) when given. Parallel over leaves; the order is deterministic.
[[nodiscard]] std::vector<Eigen::Vector3d> OccupiedPoints(
    const core::VoxelMap& map, const std::optional<Eigen::AlignedBox3d>& bounds = std::nullopt);

/// @brief The same for the voxels active in `mask` (a session's layer), whatever the fused
/// occupancy says; positions come from `map`'s point means.
[[nodiscard]] std::vector<Eigen::Vector3d> MaskedPoints(
    const core::VoxelMap& map, const openvdb::BoolGrid& mask,
    const std::optional<Eigen::AlignedBox3d>& bounds = std::nullopt);

/// @brief One point per cell of `cell_m` (the first that falls in it, in input order), keeping
/// only finite points at least `min_range_m` and (when > 0) at most `max_range_m` from the
/// origin. Deterministic.
[[nodiscard]] std::vector<Eigen::Vector3d> Downsample(const std::vector<Eigen::Vector3d>& points,
                                                      double cell_m, double min_range_m = 0.0,
                                                      double max_range_m = 0.0);

}  // namespace strata::registration
