#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "strata/core/GridTypes.hpp"

namespace strata::core {

struct VoxelMap;

/// @brief A voxel's hit count and mean endpoint, always read together, packed into one Int32 of
/// the `endpoints` grid (docs/architecture.md, "Per-voxel grids and semantics").
/// Bits 0-10: hits, saturating at kMaxHits. Bits 11-17, 18-24, 25-31: the mean's offset from the
/// voxel centre along x, y, z, quantised to 127 levels of s/127 (q = 63 is the centre; the largest
/// error of one rounding is s/254: 0.8 mm at 0.2 m). One grid of 4-byte leaves instead of a 4-byte
/// and a 12-byte one (docs/integration.md, "Memory").
namespace endpoint {

inline constexpr int kMeanBits = 7;  ///< per axis
inline constexpr int kHitBits = 32 - 3 * kMeanBits;
inline constexpr int32_t kMaxHits = (1 << kHitBits) - 1;
inline constexpr int kCentreLevel = (1 << (kMeanBits - 1)) - 1;  ///< levels 0..2c; 2c+1 unused
inline constexpr int kLevels = 2 * kCentreLevel + 1;

/// @brief The hit count of a packed value (0 for the background: no endpoint).
[[nodiscard]] inline int32_t Hits(int32_t packed) {
    return static_cast<int32_t>(static_cast<uint32_t>(packed) & uint32_t{kMaxHits});
}

/// @brief The mean endpoint's offset from the voxel centre, metres, of a packed value.
[[nodiscard]] Eigen::Vector3d Offset(int32_t packed, double voxel_size);

/// @brief Packs a hit count (saturated) and a mean offset (clamped into the voxel), rounded to
/// the nearest level.
[[nodiscard]] int32_t Pack(int64_t hits, const Eigen::Vector3d& offset, double voxel_size);

/// @brief Adds `points` endpoints whose offsets sum to `offset_sum` to a voxel's packed value:
/// m' = (m n + sum) / (n + k). The new mean is rounded up or down with a probability that makes
/// the rounding unbiased, drawn from a hash of the voxel and its count (deterministic). Rounding
/// to the nearest level instead would freeze a mean once k / (n + k) of a step is under half a
/// level: every later scan's points would be lost.
[[nodiscard]] int32_t Accumulate(int32_t packed, int64_t points, const Eigen::Vector3d& offset_sum,
                                 double voxel_size, const openvdb::Coord& ijk);

}  // namespace endpoint

/// @brief Reads hits and point means of many voxels of one map through a cached VDB accessor:
/// one reader per thread (the cache is not shared).
class EndpointReader {
public:
    explicit EndpointReader(const VoxelMap& map);
    /// @brief Points that ended in the voxel, over all scans (0: none).
    [[nodiscard]] int32_t Hits(const openvdb::Coord& ijk);
    /// @brief Where the voxel's endpoints lay (map frame): centre + mean offset; the centre when
    /// the voxel has none.
    [[nodiscard]] Eigen::Vector3d PointMean(const openvdb::Coord& ijk);

private:
    double voxel_size_;
    openvdb::Int32Grid::ConstAccessor accessor_;
};

}  // namespace strata::core
