#include "strata/core/Endpoints.hpp"

#include <algorithm>
#include <cmath>

#include "strata/core/VoxelMap.hpp"

namespace strata::core {
namespace endpoint {
namespace {

constexpr uint32_t kLevelMask = (1u << kMeanBits) - 1;

// SplitMix64's finaliser: well-mixed bits from a voxel and its count, so that the rounding of
// neighbouring voxels and of successive updates is uncorrelated.
uint64_t Mix(const openvdb::Coord& ijk, int64_t count) {
    uint64_t h = (static_cast<uint64_t>(static_cast<uint32_t>(ijk.x())) << 32) ^
                 (static_cast<uint64_t>(static_cast<uint32_t>(ijk.y())) << 11) ^
                 (static_cast<uint64_t>(static_cast<uint32_t>(ijk.z())) * 0x9E3779B97F4A7C15ull) ^
                 (static_cast<uint64_t>(count) << 48);
    h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
    return h ^ (h >> 31);
}

// Packs with level = floor(offset / step + centre + dither[a]); dither 0.5 rounds to nearest.
template <typename Dither>
int32_t PackWith(int64_t hits, const Eigen::Vector3d& offset, double voxel_size,
                 const Dither& dither) {
    const double levels_per_m = kLevels / voxel_size;
    uint32_t bits = static_cast<uint32_t>(std::clamp<int64_t>(hits, 0, kMaxHits));
    for (int a = 0; a < 3; ++a) {
        const double q = std::floor(offset[a] * levels_per_m + kCentreLevel + dither(a));
        bits |= static_cast<uint32_t>(std::clamp(q, 0.0, 2.0 * kCentreLevel))
                << (kHitBits + kMeanBits * a);
    }
    return static_cast<int32_t>(bits);
}

}  // namespace

Eigen::Vector3d Offset(int32_t packed, double voxel_size) {
    const auto bits = static_cast<uint32_t>(packed);
    const auto axis = [&](int a) {
        const auto q = static_cast<int>((bits >> (kHitBits + kMeanBits * a)) & kLevelMask);
        return (q - kCentreLevel) * (voxel_size / kLevels);
    };
    return {axis(0), axis(1), axis(2)};
}

int32_t Pack(int64_t hits, const Eigen::Vector3d& offset, double voxel_size) {
    return PackWith(hits, offset, voxel_size, [](int) { return 0.5; });
}

int32_t Accumulate(int32_t packed, int64_t points, const Eigen::Vector3d& offset_sum,
                   double voxel_size, const openvdb::Coord& ijk) {
    const int32_t before = Hits(packed);
    const int64_t after = int64_t{before} + points;
    const Eigen::Vector3d old = before > 0 ? Offset(packed, voxel_size) : Eigen::Vector3d::Zero();
    const Eigen::Vector3d mean = (old * before + offset_sum) / static_cast<double>(after);
    const uint64_t h = Mix(ijk, after);
    return PackWith(after, mean, voxel_size, [h](int a) {
        return static_cast<double>((h >> (21 * a)) & 0x1FFFFF) / double(1 << 21);
    });
}

}  // namespace endpoint

EndpointReader::EndpointReader(const VoxelMap& map)
    : voxel_size_(map.voxel_size), accessor_(map.endpoints->getConstAccessor()) {}

int32_t EndpointReader::Hits(const openvdb::Coord& ijk) {
    return endpoint::Hits(accessor_.getValue(ijk));
}

Eigen::Vector3d EndpointReader::PointMean(const openvdb::Coord& ijk) {
    const Eigen::Vector3d centre =
        (Eigen::Vector3d(ijk.x(), ijk.y(), ijk.z()) + Eigen::Vector3d::Constant(0.5)) * voxel_size_;
    int32_t packed = 0;
    return accessor_.probeValue(ijk, packed) ? centre + endpoint::Offset(packed, voxel_size_)
                                             : centre;
}

}  // namespace strata::core
