// Stage 1 of the wall pipeline: which voxels are wall candidates (column windows that vote), and
// the ground plane the slants may be measured against.
#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>
#include <vector>

#include "strata/core/GridBox.hpp"
#include "strata/core/Hash.hpp"
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
    if (window.empty()) return candidates;
    const openvdb::CoordBBox raster(openvdb::Coord(window.min_i(), window.min_j(), 0),
                                    openvdb::Coord(window.min_i() + window.width() - 1,
                                                   window.min_j() + window.height() - 1, 0));
    core::ForEachActiveInColumns(*map.occupancy, raster,
                                 [&](const openvdb::CoordBBox& voxels, float occupancy) {
                                     if (occupancy <= 0.0f) return;
                                     for (auto v = voxels.begin(); v; ++v) {
                                         const openvdb::Coord& ijk = *v;
                                         const columns::ColumnStat& w = window.At(ijk.x(), ijk.y());
                                         if (votes(w) && ijk.z() >= w.k_min + clearance)
                                             candidates.push_back(ijk);
                                     }
                                 });
    return candidates;
}

GroundPlane EstimateGround(const core::VoxelMap& map, const columns::ColumnGrid& columns,
                           uint64_t seed) {
    GroundSample sample;
    for (int j = 0; j < columns.height(); ++j) {
        for (int i = 0; i < columns.width(); ++i) {
            const openvdb::Coord column(columns.min_i() + i, columns.min_j() + j, 0);
            const columns::ColumnStat& c = columns.At(column.x(), column.y());
            if (c.voxels > 0 && sample.Admits(column.x(), column.y())) {
                sample.Add(column.x(), column.y(), map.PointMean(column.offsetBy(0, 0, c.k_min)));
            }
        }
    }
    return FitGround(sample, map.voxel_size, seed);
}

namespace {

uint64_t ColumnHash(int32_t i, int32_t j) {
    return core::Mix64((uint64_t{static_cast<uint32_t>(i)} << 32) | static_cast<uint32_t>(j));
}

bool Before(const GroundSample::Entry& a, const GroundSample::Entry& b) {
    return std::tie(a.hash, a.j, a.i) < std::tie(b.hash, b.j, b.i);
}

}  // namespace

bool GroundSample::Admits(int32_t i, int32_t j) const {
    return heap_.size() < kMaxColumns || Before(Entry{ColumnHash(i, j), j, i, 0, 0, 0}, heap_[0]);
}

void GroundSample::Add(int32_t i, int32_t j, const Eigen::Vector3d& lowest) {
    Add(Entry{ColumnHash(i, j), j, i, lowest.x(), lowest.y(), lowest.z()});
}

void GroundSample::Add(const Entry& e) {
    if (heap_.size() == kMaxColumns) {
        if (!Before(e, heap_[0])) return;
        std::pop_heap(heap_.begin(), heap_.end(), Before);
        heap_.pop_back();
    }
    heap_.push_back(e);
    std::push_heap(heap_.begin(), heap_.end(), Before);
}

std::vector<Eigen::Vector3d> GroundSample::InRasterOrder() const {
    std::vector<Entry> sorted = heap_;
    std::sort(sorted.begin(), sorted.end(), [](const Entry& a, const Entry& b) {
        return std::tie(a.j, a.i) < std::tie(b.j, b.i);
    });
    std::vector<Eigen::Vector3d> points;
    points.reserve(sorted.size());
    for (const Entry& e : sorted) points.emplace_back(e.x, e.y, e.z);
    return points;
}

GroundPlane FitGround(const GroundSample& sample, double voxel_size, uint64_t seed) {
    GroundPlane ground;
    const std::vector<Eigen::Vector3d> lowest = sample.InRasterOrder();
    if (lowest.size() < 3) return ground;
    const RansacResult r = RansacPlane(lowest, voxel_size, 200, seed);
    ground.normal = r.plane.normal.z() < 0.0 ? Eigen::Vector3d(-r.plane.normal) : r.plane.normal;
    ground.tilt_deg = SlantDeg(ground.normal);  // 0 for a level ground
    ground.columns = r.inliers;
    return ground;
}

}  // namespace strata::walls
