#include "VoxelSets.hpp"

#include <algorithm>
#include <iterator>

namespace strata::testing {

uint64_t PackKey(int32_t x, int32_t y, int32_t z) {
    constexpr int64_t kBias = int64_t{1} << 20;
    const auto u = [](int32_t v) { return static_cast<uint64_t>(v + kBias) & 0x1fffff; };
    return (u(x) << 42) | (u(y) << 21) | u(z);
}

VoxelSets StrataVoxelSets(const core::VoxelMap& map) {
    VoxelSets sets;
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        (*it > 0.0f ? sets.occupied : sets.free).push_back(PackKey(c.x(), c.y(), c.z()));
    }
    std::sort(sets.occupied.begin(), sets.occupied.end());
    std::sort(sets.free.begin(), sets.free.end());
    return sets;
}

VoxelSets OctomapVoxelSets(const octomap::OcTree& tree) {
    VoxelSets sets;
    const int depth = static_cast<int>(tree.getTreeDepth());
    const int32_t offset = 32768;
    for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
        const int level = depth - static_cast<int>(it.getDepth());
        const octomap::OcTreeKey k = it.getIndexKey();
        const int32_t n = 1 << level;
        auto& out = tree.isNodeOccupied(*it) ? sets.occupied : sets.free;
        for (int32_t dx = 0; dx < n; ++dx) {
            for (int32_t dy = 0; dy < n; ++dy) {
                for (int32_t dz = 0; dz < n; ++dz) {
                    out.push_back(
                        PackKey(k[0] - offset + dx, k[1] - offset + dy, k[2] - offset + dz));
                }
            }
        }
    }
    std::sort(sets.occupied.begin(), sets.occupied.end());
    std::sort(sets.free.begin(), sets.free.end());
    return sets;
}

double Jaccard(const std::vector<uint64_t>& a, const std::vector<uint64_t>& b) {
    if (a.empty() && b.empty()) return 1.0;
    std::vector<uint64_t> both;
    std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
    const double inter = static_cast<double>(both.size());
    return inter / (static_cast<double>(a.size() + b.size()) - inter);
}

}  // namespace strata::testing
