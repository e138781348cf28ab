// Stage 1 of the wall pipeline: which voxels are wall candidates (column windows that vote), and
// the ground plane the slants may be measured against.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "strata/geometry/PlaneFit.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::walls {

using geometry::RansacPlane;
using geometry::RansacResult;

int WindowRadius(double voxel_size, const WallConfig& config) {
    return std::max(0, static_cast<int>(std::lround(config.window_m / voxel_size / 2.0 - 0.5)));
}

int HaloVoxels(double voxel_size, const WallConfig& config) {
    // A voxel's mean lies inside it, and the observed-side test looks 2 voxels along the
    // normal from there: at most 3 voxels away on each axis.
    return std::max(WindowRadius(voxel_size, config), kObservedSideReachVoxels);
}

bool WindowVotes(const columns::ColumnStat& w, double voxel_size, int radius,
                 const WallConfig& config) {
    const double s = voxel_size;
    const double side_m = (2 * radius + 1) * s;
    return w.voxels > 0 && w.voxels * s * s / side_m >= config.min_wall_height_m &&
           w.extent_voxels() * s >= config.min_wall_height_m &&
           w.points >= config.min_window_points;
}

std::vector<openvdb::Coord> VoteCandidates(const core::VoxelMap& map,
                                           const columns::ColumnGrid& window, int radius,
                                           const WallConfig& config, size_t* voting_columns) {
    const double s = map.voxel_size;
    const int clearance = static_cast<int>(std::ceil(config.ground_clearance_m / s - 1e-9));
    auto votes = [&](const columns::ColumnStat& w) { return WindowVotes(w, s, radius, config); };
    if (voting_columns) {
        *voting_columns = 0;
        for (int j = window.min_j(); j < window.min_j() + window.height(); ++j) {
            for (int i = window.min_i(); i < window.min_i() + window.width(); ++i) {
                *voting_columns += votes(window.At(i, j));
            }
        }
    }
    std::vector<openvdb::Coord> candidates;
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it <= 0.0f) continue;
        openvdb::CoordBBox box;
        it.getBoundingBox(box);
        for (auto v = box.begin(); v; ++v) {
            const openvdb::Coord& ijk = *v;
            const columns::ColumnStat& w = window.At(ijk.x(), ijk.y());
            if (votes(w) && ijk.z() >= w.k_min + clearance) candidates.push_back(ijk);
        }
    }
    return candidates;
}

GroundPlane EstimateGround(const core::VoxelMap& map, const columns::ColumnGrid& columns,
                           uint64_t seed) {
    std::vector<Eigen::Vector3d> lowest;
    for (int j = 0; j < columns.height(); ++j) {
        for (int i = 0; i < columns.width(); ++i) {
            const openvdb::Coord column(columns.min_i() + i, columns.min_j() + j, 0);
            const columns::ColumnStat& c = columns.At(column.x(), column.y());
            if (c.voxels > 0) lowest.push_back(map.PointMean(column.offsetBy(0, 0, c.k_min)));
        }
    }
    return FitGround(std::move(lowest), map.voxel_size, seed);
}

std::vector<size_t> GroundSample(size_t columns) {
    constexpr size_t kMaxColumns = 50000;  // a sample is plenty for one plane
    std::vector<size_t> sample;
    const size_t n = std::min(columns, kMaxColumns);
    const double step = static_cast<double>(columns) / static_cast<double>(n);
    sample.reserve(n);
    for (size_t k = 0; k < n; ++k) {
        sample.push_back(columns > kMaxColumns ? static_cast<size_t>(static_cast<double>(k) * step)
                                               : k);
    }
    return sample;
}

GroundPlane FitGround(std::vector<Eigen::Vector3d> lowest, double voxel_size, uint64_t seed) {
    GroundPlane ground;
    if (lowest.size() < 3) return ground;
    const std::vector<size_t> sample = GroundSample(lowest.size());
    if (sample.size() < lowest.size()) {
        std::vector<Eigen::Vector3d> points;
        points.reserve(sample.size());
        for (size_t k : sample) points.push_back(lowest[k]);
        lowest.swap(points);
    }
    const RansacResult r = RansacPlane(lowest, voxel_size, 200, seed);
    ground.normal = r.plane.normal.z() < 0.0 ? Eigen::Vector3d(-r.plane.normal) : r.plane.normal;
    ground.tilt_deg = SlantDeg(ground.normal);  // 0 for a level ground
    ground.columns = r.inliers;
    return ground;
}

}  // namespace strata::walls
