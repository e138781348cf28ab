#pragma once
// What `strata view` sends for one tile: its voxels merged into cells of 2^lod voxels, with the
// attributes the page colours by, in a compact binary form (docs/viewer.md, "Tile format").
// Pure functions of grids: no store, no HTTP, so they can move into `pipeline` unchanged.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "strata/core/GridTypes.hpp"

namespace strata::view {

/// Coarsest level of detail: a cell of 8 voxels on a side, one OpenVDB leaf.
inline constexpr int kMaxLod = 3;

/// Bits of Cells::flags.
namespace cell_flags {
inline constexpr uint8_t kRefilled = 1;  ///< ground written by vehicle refill
inline constexpr uint8_t kCleared = 2;   ///< a vehicle voxel the vehicle analysis removed
inline constexpr uint8_t kWall = 4;      ///< part of a fitted wall (object = wall id)
inline constexpr uint8_t kFree = 8;      ///< observed free (a free-space slice)
inline constexpr uint8_t kAdded = 16;    ///< occupied after, seen free before
inline constexpr uint8_t kRemoved = 32;  ///< occupied before, seen free after
}  // namespace cell_flags

inline constexpr uint8_t kNoValue = 255;  ///< session or slant of a cell that has none

/// The grids of one tile the cells are made from. Only `occupancy` is required.
struct TileGrids {
    openvdb::FloatGrid::ConstPtr occupancy;  ///< log-odds: occupied > 0, free <= 0
    openvdb::Int32Grid::ConstPtr label;      ///< core::SemanticClass
    /// `session_<id>_occupied` layers, by ascending session id.
    std::vector<std::pair<int64_t, openvdb::BoolGrid::ConstPtr>> sessions;
    openvdb::FloatGrid::ConstPtr slant_deg;  ///< walls' products
    openvdb::Int32Grid::ConstPtr wall_id;
    openvdb::Int32Grid::ConstPtr cleared;   ///< vehicle id of each removed voxel
    openvdb::FloatGrid::ConstPtr refilled;  ///< refilled ground voxels
    // For a voxel's record only:
    openvdb::Int32Grid::ConstPtr endpoints;  ///< hits and point mean, packed (core/Endpoints.hpp)
    std::vector<std::pair<int64_t, openvdb::BoolGrid::ConstPtr>> sessions_free;
};

/// Voxels that changed between two sides: added (occupied after, seen free before) with the
/// after side's classes, removed with the before side's. Any grid may be null.
struct ChangeVoxels {
    openvdb::BoolGrid::ConstPtr added;
    openvdb::BoolGrid::ConstPtr removed;
    openvdb::Int32Grid::ConstPtr added_labels;
    openvdb::Int32Grid::ConstPtr removed_labels;
};

/// Cells of one tile at one level of detail. Cell c covers voxels [c * 2^lod, (c+1) * 2^lod).
struct Cells {
    int lod = 0;
    std::vector<openvdb::Coord> cell;  ///< cell index (voxel index >> lod)
    std::vector<uint8_t> label;        ///< most frequent class of its voxels
    std::vector<uint8_t> session;      ///< lowest session id that saw a voxel occupied (<= 254)
    std::vector<uint8_t> slant;        ///< mean slant of its wall voxels in half degrees
    std::vector<uint8_t> flags;        ///< cell_flags
    std::vector<uint16_t> object;      ///< wall id or cleared vehicle id, 0 when none
    [[nodiscard]] size_t size() const { return cell.size(); }
};

/// Occupied voxels of `tile` inside `bounds` (voxel index box), merged by 2^lod, followed by
/// the cleared vehicle voxels (flag kCleared) merged alike. Cells come leaf by leaf. Coarser
/// levels are CoarsenCells of level 0 (a coarse cell's slant is the mean of its voxels' slants
/// to half a degree).
/// @throw InvalidArgumentError when lod is outside [0, kMaxLod] or occupancy is null.
[[nodiscard]] Cells OccupiedCells(const TileGrids& tile, const openvdb::CoordBBox& bounds, int lod);
/// Level-0 cells merged by 2^lod: what OccupiedCells gives at `lod`, without the pass over the
/// tile's grids (the costly step, every active voxel).
[[nodiscard]] Cells CoarsenCells(const Cells& fine, int lod);
/// Observed free voxels inside `bounds` (flag kFree), merged by 2^lod: a slice when the box is
/// thin in z.
[[nodiscard]] Cells FreeCells(const openvdb::FloatGrid& occupancy, const openvdb::CoordBBox& bounds,
                              int lod);
/// Added voxels (flag kAdded) then removed ones (kRemoved) inside `bounds`, merged by 2^lod.
[[nodiscard]] Cells ChangeCells(const ChangeVoxels& change, const openvdb::CoordBBox& bounds,
                                int lod);

/// The binary form the page reads (little-endian; layout in docs/viewer.md): a 32-byte header
/// ("STV1", count, lod, cell size, origin of cell 0 in the map frame), int16 cell offsets from
/// that origin, then one byte each of label, session, slant, flags, then uint16 object ids.
/// @throw InvalidArgumentError when the cells span more than int16 cells on an axis.
[[nodiscard]] std::string EncodeCells(const Cells& cells, double voxel_size_m);
/// Reads EncodeCells' output back (tests, benchmarks); throws FormatError on anything else.
[[nodiscard]] Cells DecodeCells(const std::string& bytes);

}  // namespace strata::view
