#include "strata/walls/Walls.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

#include "Pieces.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/ParallelFor.hpp"
#include "strata/geometry/Clustering.hpp"
#include "strata/geometry/PlaneFit.hpp"

namespace strata::walls {

using geometry::Dbscan;
using geometry::FitPlane;
using geometry::KMeans;
using geometry::kNoise;
using geometry::Plane;
using geometry::PlaneFit;
using geometry::RansacPlane;
using geometry::RansacResult;
using geometry::RefinePlane;
using geometry::XyEigenRatio;

int PartsFor(size_t n, int divisor) {
    if (divisor < 1) throw InvalidArgumentError("K-means divisor must be >= 1");
    return std::max(1, static_cast<int>(n / static_cast<size_t>(divisor)));
}

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
    return std::chrono::duration<double>(Clock::now() - since).count();
}

void Require(bool ok, const char* what) {
    if (!ok) throw InvalidArgumentError(std::string("wall config: ") + what);
}

using detail::BoxGap;
using detail::DominantClass;
using detail::HorizontalExtent;
using detail::Piece;
using detail::SpreadOfMean;
using detail::Support;
using detail::TowardsObservedSide;
using detail::UnionFind;

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

namespace {

// The stages after voting, sharing the map, the settings and the result being filled.
class Pipeline {
public:
    Pipeline(const core::VoxelMap& map, const openvdb::BoolGrid* observed_free,
             const WallConfig& config, WallResult& result)
        : map_(map),
          observed_free_(observed_free),
          config_(config),
          result_(result),
          s_(map.voxel_size),
          threshold_(config.ransac_threshold_m > 0.0 ? config.ransac_threshold_m : 0.5 * s_) {}

    // Where a voxel's surface is: the mean of its endpoints (or its centre, for comparison).
    [[nodiscard]] Eigen::Vector3d Position(const openvdb::Coord& c) const {
        return config_.use_point_means ? map_.PointMean(c) : map_.VoxelCenter(c);
    }
    [[nodiscard]] std::vector<Eigen::Vector3d> Positions(
        const std::vector<openvdb::Coord>& voxels) const {
        std::vector<Eigen::Vector3d> points(voxels.size());
        for (size_t n = 0; n < voxels.size(); ++n) points[n] = Position(voxels[n]);
        return points;
    }

    // DBSCAN over the candidates, then K-means inside each cluster: the parts.
    [[nodiscard]] std::vector<std::pair<int, std::vector<openvdb::Coord>>> Parts(
        const std::vector<openvdb::Coord>& candidates) {
        const std::vector<int> cluster_of =
            Dbscan(candidates, config_.dbscan_eps_voxels, config_.dbscan_min_points);
        int clusters = 0;
        for (int c : cluster_of) clusters = std::max(clusters, c + 1);
        result_.stats.clusters = static_cast<size_t>(clusters);
        std::vector<std::vector<openvdb::Coord>> members(static_cast<size_t>(clusters));
        for (size_t n = 0; n < candidates.size(); ++n) {
            if (cluster_of[n] == kNoise) {
                ++result_.stats.noise_voxels;
            } else {
                members[cluster_of[n]].push_back(candidates[n]);
            }
        }
        // Each cluster's K-means on its own seed, in parallel; the parts in cluster order.
        std::vector<std::vector<std::vector<openvdb::Coord>>> local(members.size());
        core::ParallelFor(members.size(), [&](size_t c) {
            const auto& voxels = members[c];
            const int k = PartsFor(voxels.size(), config_.kmeans_divisor);
            const std::vector<int> part_of =
                KMeans(Positions(voxels), k, config_.seed + static_cast<uint64_t>(c));
            local[c].resize(static_cast<size_t>(k));
            for (size_t n = 0; n < voxels.size(); ++n) local[c][part_of[n]].push_back(voxels[n]);
        });
        std::vector<std::pair<int, std::vector<openvdb::Coord>>> parts;
        for (size_t c = 0; c < local.size(); ++c) {
            for (auto& p : local[c]) {
                if (!p.empty()) parts.emplace_back(static_cast<int>(c), std::move(p));
            }
        }
        return parts;
    }

    // What the wall tests made of one part, and the piece of a wall it became, if it passed.
    struct Judged {
        WallPart part;
        std::optional<Piece> piece;
    };

    // RANSAC on one part, then the wall tests on its inliers; a part that passes becomes a
    // piece of a wall. Reads only: parts are judged in parallel.
    [[nodiscard]] Judged Judge(int cluster, const std::vector<openvdb::Coord>& voxels,
                               uint64_t seed) const {
        Judged judged;
        WallPart& part = judged.part;
        part.cluster = cluster;
        part.voxels = voxels.size();
        part.dominant_class = DominantClass(map_, voxels);
        if (voxels.size() < config_.min_part_voxels) {
            part.verdict = PartVerdict::kTooSmall;
            return judged;
        }
        const std::vector<Eigen::Vector3d> points = Positions(voxels);
        const RansacResult ransac =
            RansacPlane(points, threshold_, config_.ransac_iterations, seed);
        std::vector<Eigen::Vector3d> inliers;
        inliers.reserve(ransac.inliers);
        Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
        for (size_t n = 0; n < points.size(); ++n) {
            if (!ransac.inlier[n]) continue;
            inliers.push_back(points[n]);
            lo = lo.cwiseMin(points[n]);
            hi = hi.cwiseMax(points[n]);
        }
        part.inliers = inliers.size();
        part.eigen_ratio = XyEigenRatio(inliers);
        part.slant_deg = SlantDeg(ransac.plane.normal, result_.up);
        part.height_m = inliers.empty() ? 0.0 : hi.z() - lo.z() + s_;
        part.length_m = HorizontalExtent(inliers, ransac.plane.normal) + s_;
        for (const auto& q : inliers) part.centroid += q;
        if (!inliers.empty()) part.centroid /= static_cast<double>(inliers.size());
        if (inliers.size() < config_.min_inlier_fraction * static_cast<double>(points.size()) ||
            inliers.size() < 3) {
            part.verdict = PartVerdict::kNotPlanar;
        } else if (part.slant_deg < config_.min_slant_deg) {
            part.verdict = PartVerdict::kNotSteep;
        } else if (part.eigen_ratio < config_.min_eigen_ratio) {
            part.verdict = PartVerdict::kNotLineLike;
        } else if (part.height_m < config_.min_part_height_m) {
            part.verdict = PartVerdict::kTooLow;
        } else if (part.length_m < config_.min_part_length_m) {
            part.verdict = PartVerdict::kTooNarrow;
        } else {
            part.verdict = PartVerdict::kWall;
            // Merging compares planes, so each piece gets the robust fit too: a RANSAC plane of
            // a facade with deep windows can be off by degrees.
            Piece piece{part.cluster, ransac.plane, part.centroid, lo, hi, voxels, points, 0};
            if (config_.refine) {
                piece.plane = RefinePlane(inliers, ransac.plane, 0.25 * threshold_);
            }
            for (const auto& q : points) {
                piece.inliers += std::abs(piece.plane.Distance(q)) <= threshold_;
            }
            judged.piece = std::move(piece);
        }
        return judged;
    }

    // Groups of pieces that are one wall: close normals, close boxes, and one piece's plane
    // holding the other's voxels nearly as well as its own.
    [[nodiscard]] std::vector<std::vector<size_t>> Merge(const std::vector<Piece>& pieces) const {
        UnionFind groups(pieces.size());
        const double cos_merge = std::cos(config_.merge_angle_deg * M_PI / 180.0);
        for (size_t a = 0; a < pieces.size(); ++a) {
            for (size_t b = a + 1; b < pieces.size(); ++b) {
                const Piece& pa = pieces[a];
                const Piece& pb = pieces[b];
                if (std::abs(pa.plane.normal.dot(pb.plane.normal)) < cos_merge) continue;
                if (BoxGap(pa, pb) > config_.merge_gap_m) continue;
                if (std::max(Support(pa, pb, threshold_), Support(pb, pa, threshold_)) <
                    config_.merge_support) {
                    continue;
                }
                groups.Join(static_cast<int>(a), static_cast<int>(b));
            }
        }
        std::vector<std::vector<size_t>> members(pieces.size());
        for (size_t a = 0; a < pieces.size(); ++a) {
            members[groups.Find(static_cast<int>(a))].push_back(a);
        }
        members.erase(
            std::remove_if(members.begin(), members.end(), [](const auto& g) { return g.empty(); }),
            members.end());
        return members;
    }

    // One plane for a whole wall: RANSAC on all its pieces' voxels (a piece's own plane may be
    // off), then the robust fit, each voxel mean weighed by the endpoints it stands for.
    // Empty when too little is left or the wall is too short.
    [[nodiscard]] std::optional<Wall> Fit(const std::vector<Piece>& pieces,
                                          const std::vector<size_t>& group) const {
        std::vector<openvdb::Coord> voxels;
        std::vector<Eigen::Vector3d> points;
        for (size_t a : group) {
            voxels.insert(voxels.end(), pieces[a].voxels.begin(), pieces[a].voxels.end());
            points.insert(points.end(), pieces[a].points.begin(), pieces[a].points.end());
        }
        Plane plane =
            RansacPlane(points, threshold_, config_.ransac_iterations, config_.seed + group[0])
                .plane;
        core::EndpointReader hits(map_);
        std::vector<Eigen::Vector3d> near;
        std::vector<double> weights;
        for (size_t n = 0; n < voxels.size(); ++n) {
            if (std::abs(plane.Distance(points[n])) > threshold_) continue;
            near.push_back(points[n]);
            weights.push_back(std::max(1, hits.Hits(voxels[n])));
        }
        if (near.size() < 3) return std::nullopt;
        plane = config_.refine ? RefinePlane(near, plane, 0.25 * threshold_, weights)
                               : FitPlane(near, weights).plane;
        Wall wall;
        std::vector<Eigen::Vector3d> inliers;
        for (size_t n = 0; n < voxels.size(); ++n) {
            if (std::abs(plane.Distance(points[n])) > threshold_) continue;
            inliers.push_back(points[n]);
            wall.voxels.push_back(voxels[n]);
        }
        if (inliers.size() < 3) return std::nullopt;
        PlaneFit fit = FitPlane(inliers);
        double sum2 = 0.0;
        for (const auto& p : inliers) sum2 += plane.Distance(p) * plane.Distance(p);
        fit.plane = plane;
        fit.rms = std::sqrt(sum2 / static_cast<double>(inliers.size()));
        wall.normal = TowardsObservedSide(map_, observed_free_, wall.voxels, plane.normal);
        wall.d = wall.normal.dot(plane.normal) > 0 ? plane.d : -plane.d;
        wall.centroid = fit.centroid;
        wall.inliers = inliers.size();
        wall.rms_m = fit.rms;
        wall.slant_deg = SlantDeg(wall.normal, result_.up);
        wall.slant_to_ground_deg = SlantDeg(wall.normal, result_.ground.normal);
        wall.lean_azimuth_deg = LeanAzimuthDeg(wall.normal, result_.up);
        // The fit's own one-sigma treats voxels as independent and misses what windows and
        // recesses do; the spread of the pieces' own slants catches that (robustly: MAD).
        std::vector<double> piece_slants;
        for (size_t a : group) piece_slants.push_back(SlantDeg(pieces[a].plane.normal, result_.up));
        wall.uncertainty_deg = std::max(SlantUncertaintyDeg(fit), SpreadOfMean(piece_slants));
        wall.eigen_ratio = XyEigenRatio(inliers);
        wall.parts = static_cast<int>(group.size());
        // A plane crosses about (|nx| + |ny| + |nz|) voxels per voxel face of its area.
        wall.area_m2 = static_cast<double>(wall.inliers) * s_ * s_ / wall.normal.cwiseAbs().sum();
        const Eigen::Vector3d along = Eigen::Vector3d::UnitZ().cross(wall.normal).normalized();
        const Eigen::Vector3d up = wall.normal.cross(along).normalized();
        double a_lo = 1e300, a_hi = -1e300, z_lo = 1e300, z_hi = -1e300;
        for (const auto& p : inliers) {
            a_lo = std::min(a_lo, p.dot(along));
            a_hi = std::max(a_hi, p.dot(along));
            z_lo = std::min(z_lo, p.dot(up));
            z_hi = std::max(z_hi, p.dot(up));
        }
        wall.length_m = a_hi - a_lo + s_;
        wall.height_m = z_hi - z_lo + s_;
        if (wall.length_m < config_.min_wall_length_m) return std::nullopt;
        return wall;
    }

private:
    const core::VoxelMap& map_;
    const openvdb::BoolGrid* observed_free_;  // null: the occupancy says what was seen free
    const WallConfig& config_;
    WallResult& result_;
    double s_;
    double threshold_;
};

}  // namespace

WallResult FindWalls(const core::VoxelMap& map, const WallConfig& config) {
    config.Validate();
    if (!map.occupancy) throw InvalidArgumentError("walls: the map has no occupancy grid");
    WallResult voted;
    const double s = map.voxel_size;
    voted.voxel_size = s;

    // 1. Column statistics, the ground and the votes.
    const auto t = Clock::now();
    const int radius = WindowRadius(s, config);
    const columns::ColumnGrid cols = columns::ColumnGrid::FromMap(map);
    voted.stats.occupied_columns = cols.OccupiedColumns();
    voted.ground = EstimateGround(map, cols, config.seed);
    const std::vector<openvdb::Coord> candidates =
        VoteCandidates(map, cols.Window(radius), radius, config, &voted.stats.voting_columns);
    voted.stats.seconds_columns = Seconds(t);
    return FindWallsAmong(map, candidates, std::move(voted), config);
}

WallResult FindWallsAmong(const core::VoxelMap& map, const std::vector<openvdb::Coord>& candidates,
                          WallResult voted, const WallConfig& config,
                          const openvdb::BoolGrid* observed_free) {
    config.Validate();
    if (!map.occupancy) throw InvalidArgumentError("walls: the map has no occupancy grid");
    WallResult result = std::move(voted);
    result.voxel_size = map.voxel_size;
    result.walls.clear();
    result.parts.clear();
    result.up = config.level_to_ground ? result.ground.normal : Eigen::Vector3d::UnitZ();
    result.stats.candidate_voxels = candidates.size();
    result.stats.clusters = result.stats.noise_voxels = 0;
    Pipeline pipeline(map, observed_free, config, result);

    // 2. DBSCAN, then K-means inside each cluster.
    auto t = Clock::now();
    const auto parts = pipeline.Parts(candidates);
    result.stats.seconds_clustering = Seconds(t);

    // 3. The wall tests per part, merging, one fit per wall. Parts and walls are judged and
    // fitted in parallel, each on its own seed, and taken in order: the result does not depend
    // on the threads.
    t = Clock::now();
    std::vector<Pipeline::Judged> judged(parts.size());
    core::ParallelFor(parts.size(), [&](size_t p) {
        judged[p] = pipeline.Judge(parts[p].first, parts[p].second, config.seed + p);
    });
    std::vector<Piece> pieces;
    for (Pipeline::Judged& j : judged) {
        result.parts.push_back(j.part);
        if (j.piece) pieces.push_back(std::move(*j.piece));
    }
    judged.clear();
    const std::vector<std::vector<size_t>> groups = pipeline.Merge(pieces);
    std::vector<std::optional<Wall>> fitted(groups.size());
    core::ParallelFor(groups.size(),
                      [&](size_t g) { fitted[g] = pipeline.Fit(pieces, groups[g]); });
    for (std::optional<Wall>& wall : fitted) {
        if (wall) result.walls.push_back(std::move(*wall));
    }
    std::sort(result.walls.begin(), result.walls.end(),
              [](const Wall& a, const Wall& b) { return a.inliers > b.inliers; });
    for (size_t w = 0; w < result.walls.size(); ++w) result.walls[w].id = static_cast<int>(w + 1);
    result.stats.seconds_fitting = Seconds(t);
    return result;
}

}  // namespace strata::walls
