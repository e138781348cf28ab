#include "strata/geometry/Grouping.hpp"

#include <deque>

#include "strata/core/GridTypes.hpp"

namespace strata::geometry {

std::vector<std::vector<openvdb::Coord>> GroupVoxels(const std::vector<openvdb::Coord>& voxels,
                                                     int reach_voxels) {
    // Index of every voxel, as a sparse lookup shaped like the set.
    openvdb::Int32Tree index(-1);
    {
        openvdb::tree::ValueAccessor<openvdb::Int32Tree> acc(index);
        for (size_t i = 0; i < voxels.size(); ++i) acc.setValue(voxels[i], static_cast<int>(i));
    }
    openvdb::tree::ValueAccessor<const openvdb::Int32Tree> acc(index);
    const int r = reach_voxels;
    std::vector<bool> seen(voxels.size(), false);
    std::vector<std::vector<openvdb::Coord>> groups;
    std::deque<int> queue;
    for (size_t seed = 0; seed < voxels.size(); ++seed) {
        if (seen[seed]) continue;
        std::vector<openvdb::Coord>& group = groups.emplace_back();
        seen[seed] = true;
        queue.push_back(static_cast<int>(seed));
        while (!queue.empty()) {
            const openvdb::Coord c = voxels[queue.front()];
            queue.pop_front();
            group.push_back(c);
            for (int dx = -r; dx <= r; ++dx) {
                for (int dy = -r; dy <= r; ++dy) {
                    for (int dz = -r; dz <= r; ++dz) {
                        int j = -1;
                        if (acc.probeValue(c.offsetBy(dx, dy, dz), j) && !seen[j]) {
                            seen[j] = true;
                            queue.push_back(j);
                        }
                    }
                }
            }
        }
    }
    return groups;
}

}  // namespace strata::geometry
