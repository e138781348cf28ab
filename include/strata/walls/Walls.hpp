#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "strata/columns/ColumnStats.hpp"
#include "strata/core/GridTypes.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/walls/Slant.hpp"

namespace strata::walls {

/// @brief Settings of the wall pipeline (docs/walls.md explains each stage and default).
struct WallConfig {
    // 1. Column statistics and voting.
    double window_m = 1.0;  ///< side of the sliding x/y window (rounded to an odd voxel count)
    /// A window votes for walls when it holds at least this much occupied surface per metre of
    /// window side (occupied voxels x voxel area / window side, m^2/m: a vertical wall of height
    /// h crossing the window gives h) and its occupied voxels span at least this height. Counting
    /// voxels rather than points makes the vote independent of point density and range, as long
    /// as the scanner puts a point into each surface voxel.
    double min_wall_height_m = 2.0;
    /// The study's rule, optionally on top: at least this many points (`hits`) per window
    /// (500 for its backpack scanner and 1 m windows); 0 = off.
    int64_t min_window_points = 0;
    /// Candidate voxels start this far above the lowest occupied voxel of their window (ground).
    double ground_clearance_m = 0.4;

    // 2. Clustering.
    double dbscan_eps_voxels = 2.0;  ///< neighbour radius of DBSCAN, in voxels
    int dbscan_min_points = 6;       ///< neighbours (itself included) that make a core voxel
    int kmeans_divisor = 400;        ///< K-means parts per cluster: k = floor(n / divisor)

    // 3. Per part: RANSAC plane and the wall tests.
    double ransac_threshold_m = 0.0;  ///< inlier distance; 0 = half a voxel
    int ransac_iterations = 200;
    size_t min_part_voxels = 30;        ///< smaller parts are dropped as clutter
    double min_inlier_fraction = 0.45;  ///< a part's voxels on its plane
    double min_eigen_ratio = 1.7;       ///< x/y eigenvalue ratio of the inliers (the study's 1.7)
    double min_slant_deg = 75.0;        ///< flatter planes (ground, roofs, canopies) are not walls
    double min_part_height_m = 1.5;     ///< vertical extent of a part's inliers
    double min_part_length_m = 1.0;     ///< horizontal extent along the plane (tree trunks fail)

    // 4. Walls: coplanar accepted parts merge, then one refined fit per wall.
    double merge_angle_deg = 10.0;  ///< two parts merge when their normals are this close, ...
    double merge_gap_m = 1.0;       ///< ... the boxes of their inliers this close, and ...
    /// ... one part's plane holds this fraction as many of the other's voxels as its own plane
    /// does (so a part whose own fit went astray still joins the wall it lies on).
    double merge_support = 0.7;
    bool refine = true;              ///< Ceres refinement with a Cauchy loss
    double min_wall_length_m = 1.0;  ///< horizontal extent of a wall's inliers
    uint64_t seed = 1;               ///< RANSAC and K-means seeds (results are deterministic)
    /// Measure slants against the normal of the ground plane instead of the map's z axis: for
    /// maps whose frame is not level (odometry that starts in a tilted sensor frame). Sloped
    /// streets then bias every slant by their slope, so the default is the map's z axis.
    bool level_to_ground = false;
    /// Fit planes to the mean endpoint of each voxel (`point_mean`); false fits voxel centres
    /// (for comparison: docs/walls.md shows what each choice costs).
    bool use_point_means = true;

    /// @brief Throws InvalidArgumentError naming the first bad field.
    void Validate() const;
};

/// @brief The study's rule for the number of K-means parts of a cluster: floor(n / divisor),
/// at least 1.
[[nodiscard]] int PartsFor(size_t n, int divisor);

/// @brief One wall: a plane fitted to the voxels (their centres) of one or more parts.
struct Wall {
    int id = 0;                         ///< 1, 2, ... by decreasing inlier count
    double slant_deg = 90.0;            ///< SlantDeg(normal, WallResult::up): 90 = vertical
    double slant_to_ground_deg = 90.0;  ///< SlantDeg(normal, WallResult::ground.normal)
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< of the inliers, map frame
    Eigen::Vector3d normal = Eigen::Vector3d::UnitX();   ///< unit, towards the observed side
    double d = 0.0;                                      ///< plane: normal . x + d = 0
    size_t inliers = 0;    ///< voxels within the RANSAC threshold of the plane
    double area_m2 = 0.0;  ///< surface the inlier voxels cover
    double rms_m = 0.0;    ///< of the inliers' distances to the plane
    /// One-sigma slant uncertainty: the larger of the fit's (voxels taken as independent) and
    /// the spread (MAD) of its parts' slants over the square root of their number.
    double uncertainty_deg = 0.0;
    double lean_azimuth_deg = 0.0;       ///< LeanAzimuthDeg(normal)
    double length_m = 0.0;               ///< horizontal extent of the inliers along the wall
    double height_m = 0.0;               ///< vertical extent of the inliers
    double eigen_ratio = 0.0;            ///< x/y eigenvalue ratio of the inliers
    int parts = 0;                       ///< K-means parts merged into this wall
    std::vector<openvdb::Coord> voxels;  ///< the inlier voxels
};

/// @brief Why a K-means part was or was not taken as (a piece of) a wall.
enum class PartVerdict {
    kWall,
    kTooSmall,
    kNotPlanar,
    kNotLineLike,
    kNotSteep,
    kTooLow,
    kTooNarrow,
};
[[nodiscard]] const char* VerdictName(PartVerdict v);

/// @brief One K-means part, for diagnostics and tests.
struct WallPart {
    int cluster = 0;
    size_t voxels = 0;
    size_t inliers = 0;
    double eigen_ratio = 0.0;
    double slant_deg = 0.0;
    double height_m = 0.0;
    double length_m = 0.0;  ///< horizontal extent of the inliers along the plane
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    /// Most frequent fused class of its voxels (kUnknown on maps without labels).
    core::SemanticClass dominant_class = core::SemanticClass::kUnknown;
    PartVerdict verdict = PartVerdict::kTooSmall;
};

/// @brief Counts of each stage, and where the time went.
struct WallStats {
    size_t occupied_columns = 0;
    size_t voting_columns = 0;
    size_t candidate_voxels = 0;
    size_t clusters = 0;
    size_t noise_voxels = 0;  ///< candidates DBSCAN left unclustered
    double seconds_columns = 0.0, seconds_clustering = 0.0, seconds_fitting = 0.0;
};

/// @brief The ground plane of a map: RANSAC over the lowest occupied voxel of every column.
struct GroundPlane {
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, upwards
    double tilt_deg = 0.0;                              ///< angle between normal and map z
    size_t columns = 0;                                 ///< columns on the plane
};

/// @brief Fits the ground plane (threshold: one voxel). A tilt of a degree or more on a flat
/// site says the map's frame is not level: its slants are then off by as much.
[[nodiscard]] GroundPlane EstimateGround(const core::VoxelMap& map,
                                         const columns::ColumnGrid& columns, uint64_t seed = 1);

struct WallResult {
    std::vector<Wall> walls;
    GroundPlane ground;
    Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< what slants were measured against
    std::vector<WallPart> parts;
    WallStats stats;
    double voxel_size = 0.0;
};

/// @brief Radius in columns of the voting window: `window_m` rounded to an odd voxel count.
[[nodiscard]] int WindowRadius(double voxel_size, const WallConfig& config);

/// @brief Stage 1's rule: whether a column's window statistics vote for walls.
[[nodiscard]] bool WindowVotes(const columns::ColumnStat& window, double voxel_size, int radius,
                               const WallConfig& config);

/// How far the observed-side test looks from a voxel: 2 voxels along the normal from its mean.
inline constexpr int kObservedSideReachVoxels = 3;

/// @brief How far (x/y voxels) a part of a map must reach beyond its own columns for the walls
/// of the whole map to be found from its parts: the voting window's radius, and the 3 voxels the
/// observed-side test looks from a voxel (2 voxels along the normal from its mean).
[[nodiscard]] int HaloVoxels(double voxel_size, const WallConfig& config);

/// @brief The columns the ground plane is fitted to: of the occupied columns' lowest voxels, the
/// kMaxColumns whose column hashes lowest (all of them on a smaller map). Which columns those
/// are depends on nothing but the columns, so a map read in parts, in any order, keeps only
/// these and samples as the whole map does.
class GroundSample {
public:
    static constexpr size_t kMaxColumns = 50000;  ///< a sample is plenty for one plane
    struct Entry {
        uint64_t hash;
        int32_t j, i;
        double x, y, z;  ///< the mean of the column's lowest voxel (map frame)
    };
    /// @brief Whether column (i, j) would be kept now (so its mean need not be computed else).
    [[nodiscard]] bool Admits(int32_t i, int32_t j) const;
    /// @brief Offers column (i, j) and the mean of its lowest voxel; each column once.
    void Add(int32_t i, int32_t j, const Eigen::Vector3d& lowest);
    /// @brief Offers a column another sample kept.
    void Add(const Entry& e);
    /// @brief The kept columns (in no particular order), e.g. to send them to another process.
    [[nodiscard]] const std::vector<Entry>& entries() const { return heap_; }
    /// @brief The kept columns' means in raster order (j, then i).
    [[nodiscard]] std::vector<Eigen::Vector3d> InRasterOrder() const;

private:
    std::vector<Entry> heap_;  // a max-heap by (hash, j, i): its top is the first to go
};

/// @brief The ground plane of the sampled lowest voxels: RANSAC with a one-voxel threshold.
[[nodiscard]] GroundPlane FitGround(const GroundSample& sample, double voxel_size,
                                    uint64_t seed = 1);

/// @brief Stage 1 (voting): the occupied voxels of the columns whose window votes for walls,
/// minus the ground at the bottom of the window. `window` is columns.Window(radius).
[[nodiscard]] std::vector<openvdb::Coord> VoteCandidates(const core::VoxelMap& map,
                                                         const columns::ColumnGrid& window,
                                                         int radius, const WallConfig& config,
                                                         size_t* voting_columns = nullptr);

/// @brief The whole pipeline on a map (docs/walls.md, "Pipeline"): column statistics, voting,
/// DBSCAN, K-means, RANSAC + wall tests per part, merge, SVD + Ceres per wall. The stages after
/// voting run in parallel (TBB). Throws InvalidArgumentError for a bad config or a map without
/// occupancy.
[[nodiscard]] WallResult FindWalls(const core::VoxelMap& map, const WallConfig& config = {});

/// @brief The stages after voting (DBSCAN, K-means, the wall tests, merging, one fit per wall),
/// fed the candidates a few connected groups at a time, as a map read tile by tile yields them,
/// or all at once (FindWallsAmong): the walls do not depend on how the candidates were split or
/// in which order the groups came. Every stage takes voxels in Coord's order and draws its seed
/// from them (K-means from its cluster's first voxel, RANSAC also from the part's number in it),
/// clusters are numbered in order of their first voxel, and walls are ordered by inliers, then
/// by their first part.
class WallAssembler {
public:
    /// `map` must hold the endpoints and labels of every candidate added and not fitted yet,
    /// and the occupancy within HaloVoxels of them (or `observed_free` those of them seen free,
    /// as for FindWallsAmong); the rest of it is never read. Slants are measured against `up`
    /// (UpOf).
    /// @throw InvalidArgumentError for a bad config or a map without occupancy.
    WallAssembler(const core::VoxelMap& map, const WallConfig& config, const Eigen::Vector3d& up,
                  const openvdb::BoolGrid* observed_free = nullptr);
    ~WallAssembler();
    WallAssembler(const WallAssembler&) = delete;
    WallAssembler& operator=(const WallAssembler&) = delete;

    /// @brief DBSCAN, K-means and the wall tests on whole groups of
    /// geometry::ConnectedVoxels(candidates, config.dbscan_eps_voxels), in parallel.
    void Add(const std::vector<std::vector<openvdb::Coord>>& groups);
    /// @brief Merges and fits the walls none of whose pieces comes within merge_gap_m (and a
    /// voxel) of a voxel box `open` says more candidates may still come to.
    void FitSettled(const std::function<bool(const openvdb::CoordBBox&)>& open);
    /// @brief How many walls have been fitted so far (each kept until Finish).
    [[nodiscard]] size_t fitted() const;
    /// @brief The voxel boxes of the accepted parts not fitted yet: what `map` must still hold.
    [[nodiscard]] std::vector<openvdb::CoordBBox> PendingBoxes() const;
    /// @brief What was added and not finished (parts, fitted walls, pieces still waiting) as
    /// bytes for another process's assembler of the same job (Absorb); leaves this one empty.
    [[nodiscard]] std::string Release();
    /// @brief Takes over what another assembler released: its parts and walls as they are, its
    /// waiting pieces as this one's (`map` must hold what they read).
    /// @throw FormatError when the bytes are cut short.
    void Absorb(const std::string& bytes);
    /// @brief Fits what is left; the result, with stage 1's ground and counts from `voted`.
    /// Call once.
    [[nodiscard]] WallResult Finish(WallResult voted);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// @brief What slants are measured against: the map's z axis, or with `level_to_ground` the
/// ground's normal.
[[nodiscard]] Eigen::Vector3d UpOf(const WallConfig& config, const GroundPlane& ground);

/// @brief The stages after voting on `candidates` (any order): one WallAssembler fed them all.
/// `voted` brings stage 1's ground and counts. `map` needs the endpoints and labels of the
/// candidates and the occupancy within HaloVoxels of them, nothing else: FindWalls(map) is
/// FindWallsAmong(map, VoteCandidates(...), ...), and a map read tile by tile gives the same
/// walls from only those voxels (pipeline::FindWalls). Only whether a voxel was seen free
/// (occupancy <= 0) is read of the occupancy: `observed_free`, when given, holds those voxels
/// (a sixteenth of a FloatGrid's memory) and the occupancy is not read.
[[nodiscard]] WallResult FindWallsAmong(const core::VoxelMap& map,
                                        const std::vector<openvdb::Coord>& candidates,
                                        WallResult voted, const WallConfig& config,
                                        const openvdb::BoolGrid* observed_free = nullptr);

}  // namespace strata::walls
