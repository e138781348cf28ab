#include "strata/walls/Walls.hpp"

#include <algorithm>
#include <string>
#include <utility>

#include "strata/core/Elapsed.hpp"
#include "strata/core/Error.hpp"
#include "strata/geometry/Clustering.hpp"

namespace strata::walls {

int PartsFor(size_t n, int divisor) {
    if (divisor < 1) throw InvalidArgumentError("K-means divisor must be >= 1");
    return std::max(1, static_cast<int>(n / static_cast<size_t>(divisor)));
}

namespace {

void Require(bool ok, const char* what) {
    if (!ok) throw InvalidArgumentError(std::string("wall config: ") + what);
}

}  // namespace

const char* VerdictName(PartVerdict v) {
    switch (v) {
        case PartVerdict::kWall:
            return "wall";
        case PartVerdict::kTooSmall:
            return "too_small";
        case PartVerdict::kNotPlanar:
            return "not_planar";
        case PartVerdict::kNotLineLike:
            return "not_line_like";
        case PartVerdict::kNotSteep:
            return "not_steep";
        case PartVerdict::kTooLow:
            return "too_low";
        case PartVerdict::kTooNarrow:
            return "too_narrow";
    }
    return "unknown";
}

void WallConfig::Validate() const {
    Require(window_m > 0.0, "window_m must be > 0");
    Require(min_wall_height_m >= 0.0, "min_wall_height_m must be >= 0");
    Require(min_window_points >= 0, "min_window_points must be >= 0");
    Require(ground_clearance_m >= 0.0, "ground_clearance_m must be >= 0");
    Require(dbscan_eps_voxels >= 1.0, "dbscan_eps_voxels must be >= 1");
    Require(dbscan_min_points >= 1, "dbscan_min_points must be >= 1");
    Require(kmeans_divisor >= 1, "kmeans_divisor must be >= 1");
    Require(ransac_threshold_m >= 0.0, "ransac_threshold_m must be >= 0");
    Require(ransac_iterations >= 1, "ransac_iterations must be >= 1");
    Require(min_part_voxels >= 3, "min_part_voxels must be >= 3");
    Require(min_inlier_fraction >= 0.0 && min_inlier_fraction <= 1.0,
            "min_inlier_fraction must be in [0, 1]");
    Require(min_eigen_ratio >= 1.0, "min_eigen_ratio must be >= 1");
    Require(min_slant_deg >= 0.0 && min_slant_deg <= 90.0, "min_slant_deg must be in [0, 90]");
    Require(min_part_height_m >= 0.0, "min_part_height_m must be >= 0");
    Require(min_part_length_m >= 0.0, "min_part_length_m must be >= 0");
    Require(merge_angle_deg >= 0.0 && merge_angle_deg <= 90.0,
            "merge_angle_deg must be in [0, 90]");
    Require(merge_gap_m >= 0.0, "merge_gap_m must be >= 0");
    Require(merge_support >= 0.0 && merge_support <= 1.0, "merge_support must be in [0, 1]");
    Require(min_wall_length_m >= 0.0, "min_wall_length_m must be >= 0");
}

Eigen::Vector3d UpOf(const WallConfig& config, const GroundPlane& ground) {
    return config.level_to_ground ? ground.normal : Eigen::Vector3d::UnitZ();
}

WallResult FindWalls(const core::VoxelMap& map, const WallConfig& config) {
    config.Validate();
    if (!map.occupancy) throw InvalidArgumentError("walls: the map has no occupancy grid");
    WallResult voted;
    const double s = map.voxel_size;
    voted.voxel_size = s;

    // 1. Column statistics, the ground and the votes.
    const auto t = core::Clock::now();
    const int radius = WindowRadius(s, config);
    const columns::ColumnGrid cols = columns::ColumnGrid::FromMap(map);
    voted.stats.occupied_columns = cols.OccupiedColumns();
    voted.ground = EstimateGround(map, cols, config.seed);
    const std::vector<openvdb::Coord> candidates =
        VoteCandidates(map, cols.Window(radius), radius, config, &voted.stats.voting_columns);
    voted.stats.seconds_columns = core::SecondsSince(t);
    return FindWallsAmong(map, candidates, std::move(voted), config);
}

WallResult FindWallsAmong(const core::VoxelMap& map, const std::vector<openvdb::Coord>& candidates,
                          WallResult voted, const WallConfig& config,
                          const openvdb::BoolGrid* observed_free) {
    WallAssembler walls(map, config, UpOf(config, voted.ground), observed_free);
    walls.Add(geometry::ConnectedVoxels(candidates, config.dbscan_eps_voxels));
    return walls.Finish(std::move(voted));
}

}  // namespace strata::walls
