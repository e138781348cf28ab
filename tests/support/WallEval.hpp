#pragma once
// Walls found in a map scored against the simulator's ground truth (ground_truth.json): shared by
// the street's wall test (tests/walls) and the district's accuracy test (tests/sim).
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "strata/core/VoxelMap.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::testing {

// A detected wall's voxel is on a truth wall when this close to its plane and inside its front
// polygon grown by the same margin; a wall is found by the detection with most such voxels,
// when it has at least kMinWallMatchVoxels of them and normals agree within kMaxWallMatchDeg.
inline constexpr double kWallMatchDistanceM = 0.3;
inline constexpr size_t kMinWallMatchVoxels = 20;
inline constexpr double kMaxWallMatchDeg = 10.0;
// Walls the targets count: longer than this.
inline constexpr double kMinTruthWallLengthM = 3.0;

/// One straight wall of ground_truth.json.
struct TruthWall {
    int id = 0;
    std::string name, kind;
    double slant_deg = 90.0;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    double d = 0.0;
    Eigen::Vector3d origin, u, v;  ///< polygon corner 0 and the edges to corners 1 and 3
    [[nodiscard]] double length() const { return u.norm(); }
    /// On the plane (within the margin) and inside the grown front polygon.
    [[nodiscard]] bool Holds(const Eigen::Vector3d& p) const;
};

/// The walls of a ground_truth.json (in its session frame).
[[nodiscard]] std::vector<TruthWall> ReadTruthWalls(const std::filesystem::path& ground_truth);

struct WallMatch {
    const TruthWall* truth = nullptr;
    const walls::Wall* wall = nullptr;  ///< null when not found
    size_t voxels = 0;
};

/// The detection that best matches each truth wall.
[[nodiscard]] std::vector<WallMatch> MatchWalls(const std::vector<TruthWall>& truth,
                                                const core::VoxelMap& map,
                                                const walls::WallResult& result);

struct WallScore {
    size_t counted = 0, found = 0, vegetation = 0, vegetation_as_wall = 0;
    double mean_error = 0.0, max_error = 0.0;  ///< slant errors of the walls found, degrees
};

/// Scores one run on the truth walls longer than kMinTruthWallLengthM; `table` prints the
/// per-wall rows docs/walls.md shows.
[[nodiscard]] WallScore ScoreWalls(const std::vector<TruthWall>& truth, const core::VoxelMap& map,
                                   const walls::WallResult& result, bool table);

}  // namespace strata::testing
