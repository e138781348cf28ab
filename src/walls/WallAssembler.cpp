// The stages after voting (docs/walls.md, "Pipeline" 4-9): DBSCAN per group of candidates, K-means
// per cluster, the wall tests per part, merging and one fit per wall, fed as a map read tile by
// tile yields the candidates. Every order is Coord's and every seed is drawn from the voxels, so
// the walls do not depend on how the candidates were split.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <utility>

#include "Handover.hpp"
#include "Pieces.hpp"
#include "strata/core/Endpoints.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Hash.hpp"
#include "strata/core/ParallelFor.hpp"
#include "strata/geometry/Clustering.hpp"
#include "strata/geometry/PlaneFit.hpp"
#include "strata/walls/Walls.hpp"

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

namespace {

using Clock = std::chrono::steady_clock;

double Elapsed(Clock::time_point since) {
    return std::chrono::duration<double>(Clock::now() - since).count();
}

using detail::BoxGap;
using detail::DominantClass;
using detail::HorizontalExtent;
using detail::PartKey;
using detail::Piece;
using detail::SpreadOfMean;
using detail::Support;
using detail::TowardsObservedSide;
using detail::UnionFind;

// A seed drawn from a voxel and a number (SplitMix64 of each in turn): the same wherever the
// voxel's group of candidates was read.
uint64_t SeedOf(uint64_t seed, const openvdb::Coord& c, uint64_t n) {
    uint64_t h = core::Mix64(seed);
    for (const int32_t v : {c.x(), c.y(), c.z()}) h = core::Mix64(h ^ static_cast<uint32_t>(v));
    return core::Mix64(h ^ n);
}

}  // namespace

struct WallAssembler::Impl {
    Impl(const core::VoxelMap& map, const WallConfig& config, const Eigen::Vector3d& up,
         const openvdb::BoolGrid* observed_free)
        : map_(map),
          observed_free_(observed_free),
          config_(config),
          up_(up),
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

    // DBSCAN of each group, then K-means inside each cluster: the parts, named by their key.
    [[nodiscard]] std::vector<std::pair<PartKey, std::vector<openvdb::Coord>>> Parts(
        const std::vector<std::vector<openvdb::Coord>>& groups) {
        std::vector<std::vector<int>> cluster_of(groups.size());
        core::ParallelFor(groups.size(), [&](size_t g) {
            cluster_of[g] = Dbscan(groups[g], config_.dbscan_eps_voxels, config_.dbscan_min_points);
        });
        // Each cluster's voxels in Coord's order (a group's own); its key is the first.
        std::vector<std::vector<openvdb::Coord>> members;
        for (size_t g = 0; g < groups.size(); ++g) {
            const size_t first = members.size();
            for (size_t n = 0; n < groups[g].size(); ++n) {
                const int c = cluster_of[g][n];
                if (c == kNoise) {
                    ++stats_.noise_voxels;
                    continue;
                }
                if (first + static_cast<size_t>(c) >= members.size()) {
                    members.resize(first + static_cast<size_t>(c) + 1);
                }
                members[first + static_cast<size_t>(c)].push_back(groups[g][n]);
            }
        }
        stats_.clusters += members.size();
        // Each cluster's K-means on a seed of its own, in parallel; parts in cluster order.
        std::vector<std::vector<std::vector<openvdb::Coord>>> local(members.size());
        core::ParallelFor(members.size(), [&](size_t c) {
            const auto& voxels = members[c];
            const int k = PartsFor(voxels.size(), config_.kmeans_divisor);
            const std::vector<int> part_of =
                KMeans(Positions(voxels), k, SeedOf(config_.seed, voxels.front(), 0));
            local[c].resize(static_cast<size_t>(k));
            for (size_t n = 0; n < voxels.size(); ++n) local[c][part_of[n]].push_back(voxels[n]);
        });
        std::vector<std::pair<PartKey, std::vector<openvdb::Coord>>> parts;
        for (size_t c = 0; c < local.size(); ++c) {
            for (size_t p = 0; p < local[c].size(); ++p) {
                if (local[c][p].empty()) continue;
                parts.emplace_back(PartKey{members[c].front(), static_cast<int>(p)},
                                   std::move(local[c][p]));
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
    [[nodiscard]] Judged Judge(const PartKey& key,
                               const std::vector<openvdb::Coord>& voxels) const {
        Judged judged;
        WallPart& part = judged.part;
        part.voxels = voxels.size();
        part.dominant_class = DominantClass(map_, voxels);
        if (voxels.size() < config_.min_part_voxels) {
            part.verdict = PartVerdict::kTooSmall;
            return judged;
        }
        const std::vector<Eigen::Vector3d> points = Positions(voxels);
        const RansacResult ransac =
            RansacPlane(points, threshold_, config_.ransac_iterations,
                        SeedOf(config_.seed, key.cluster, 1 + static_cast<uint64_t>(key.part)));
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
        part.slant_deg = SlantDeg(ransac.plane.normal, up_);
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
            Piece piece{ransac.plane, part.centroid, lo, hi, voxels, points, 0};
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

    // Whether two pieces are one wall: close normals, close boxes, and one piece's plane
    // holding the other's voxels nearly as well as its own.
    [[nodiscard]] bool OneWall(const Piece& a, const Piece& b) const {
        const double cos_merge = std::cos(config_.merge_angle_deg * M_PI / 180.0);
        return std::abs(a.plane.normal.dot(b.plane.normal)) >= cos_merge &&
               BoxGap(a, b) <= config_.merge_gap_m &&
               std::max(Support(a, b, threshold_), Support(b, a, threshold_)) >=
                   config_.merge_support;
    }

    // The voxels a piece comes near enough to for a later piece there to merge with it: its
    // box grown by the merge gap and a voxel (a piece's means lie inside its voxels).
    [[nodiscard]] openvdb::CoordBBox Reach(const Piece& p) const {
        const Eigen::Vector3d gap = Eigen::Vector3d::Constant(config_.merge_gap_m);
        openvdb::CoordBBox box(map_.WorldToVoxel(p.lo - gap), map_.WorldToVoxel(p.hi + gap));
        box.expand(1);
        return box;
    }

    // One plane for a whole wall: RANSAC on all its pieces' voxels (a piece's own plane may be
    // off), then the robust fit, each voxel mean weighed by the endpoints it stands for.
    // Empty when too little is left or the wall is too short. `group` is in key order.
    [[nodiscard]] std::optional<Wall> Fit(const std::vector<const Piece*>& group,
                                          const PartKey& first) const {
        std::vector<openvdb::Coord> voxels;
        std::vector<Eigen::Vector3d> points;
        for (const Piece* piece : group) {
            voxels.insert(voxels.end(), piece->voxels.begin(), piece->voxels.end());
            points.insert(points.end(), piece->points.begin(), piece->points.end());
        }
        // The wall's seed is drawn apart from its first part's (which has number 1 + part).
        Plane plane = RansacPlane(points, threshold_, config_.ransac_iterations,
                                  SeedOf(config_.seed, first.cluster,
                                         (uint64_t{1} << 32) + static_cast<uint64_t>(first.part)))
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
        wall.slant_deg = SlantDeg(wall.normal, up_);
        wall.lean_azimuth_deg = LeanAzimuthDeg(wall.normal, up_);
        // The fit's own one-sigma treats voxels as independent and misses what windows and
        // recesses do; the spread of the pieces' own slants catches that (robustly: MAD).
        std::vector<double> piece_slants;
        for (const Piece* piece : group) piece_slants.push_back(SlantDeg(piece->plane.normal, up_));
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

    void Add(const std::vector<std::vector<openvdb::Coord>>& groups) {
        auto t = Clock::now();
        const auto parts = Parts(groups);
        stats_.seconds_clustering += Elapsed(t);
        t = Clock::now();
        std::vector<Judged> judged(parts.size());
        core::ParallelFor(parts.size(),
                          [&](size_t p) { judged[p] = Judge(parts[p].first, parts[p].second); });
        for (size_t p = 0; p < parts.size(); ++p) {
            parts_.emplace_back(parts[p].first, std::move(judged[p].part));
            if (judged[p].piece) pieces_.emplace_back(parts[p].first, std::move(*judged[p].piece));
        }
        stats_.seconds_fitting += Elapsed(t);
    }

    // The pieces in groups that are one wall (pieces linked through OneWall), each in key
    // order, the groups in order of their first piece.
    [[nodiscard]] std::vector<std::vector<size_t>> Merge() {
        std::sort(pieces_.begin(), pieces_.end(),
                  [](const auto& a, const auto& b) { return a.first < b.first; });
        UnionFind sets(pieces_.size());
        for (size_t a = 0; a < pieces_.size(); ++a) {
            for (size_t b = a + 1; b < pieces_.size(); ++b) {
                if (OneWall(pieces_[a].second, pieces_[b].second)) {
                    sets.Join(static_cast<int>(a), static_cast<int>(b));
                }
            }
        }
        std::vector<std::vector<size_t>> members(pieces_.size());
        for (size_t a = 0; a < pieces_.size(); ++a) {
            members[sets.Find(static_cast<int>(a))].push_back(a);
        }
        members.erase(
            std::remove_if(members.begin(), members.end(), [](const auto& g) { return g.empty(); }),
            members.end());
        std::sort(members.begin(), members.end());
        return members;
    }

    void FitSettled(const std::function<bool(const openvdb::CoordBBox&)>& open) {
        const auto t = Clock::now();
        std::vector<std::vector<size_t>> settled;
        std::vector<bool> fitted(pieces_.size(), false);
        for (std::vector<size_t>& group : Merge()) {
            const bool waits = open && std::any_of(group.begin(), group.end(), [&](size_t a) {
                                   return open(Reach(pieces_[a].second));
                               });
            if (waits) continue;
            for (size_t a : group) fitted[a] = true;
            settled.push_back(std::move(group));
        }
        std::vector<std::optional<Wall>> walls(settled.size());
        core::ParallelFor(settled.size(), [&](size_t g) {
            std::vector<const Piece*> group;
            for (size_t a : settled[g]) group.push_back(&pieces_[a].second);
            walls[g] = Fit(group, pieces_[settled[g].front()].first);
        });
        for (size_t g = 0; g < settled.size(); ++g) {
            if (walls[g])
                walls_.emplace_back(pieces_[settled[g].front()].first, std::move(*walls[g]));
        }
        size_t kept = 0;
        for (size_t a = 0; a < pieces_.size(); ++a) {
            if (fitted[a]) continue;
            if (kept != a) pieces_[kept] = std::move(pieces_[a]);
            ++kept;
        }
        pieces_.resize(kept);
        stats_.seconds_fitting += Elapsed(t);
    }

    [[nodiscard]] std::vector<openvdb::CoordBBox> PendingBoxes() const {
        std::vector<openvdb::CoordBBox> boxes;
        for (const auto& [key, piece] : pieces_) {
            openvdb::CoordBBox box;
            for (const openvdb::Coord& c : piece.voxels) box.expand(c);
            boxes.push_back(box);
        }
        return boxes;
    }

    WallResult Finish(WallResult result) {
        FitSettled({});
        result.voxel_size = s_;
        result.up = up_;
        result.walls.clear();
        result.parts.clear();
        result.stats.candidate_voxels = stats_.candidate_voxels;
        result.stats.clusters = stats_.clusters;
        result.stats.noise_voxels = stats_.noise_voxels;
        result.stats.seconds_clustering = stats_.seconds_clustering;
        result.stats.seconds_fitting = stats_.seconds_fitting;
        // Parts by cluster (numbered in order of their first voxel), walls by inliers.
        std::stable_sort(parts_.begin(), parts_.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
        int cluster = -1;
        for (size_t p = 0; p < parts_.size(); ++p) {
            if (p == 0 || parts_[p].first.cluster != parts_[p - 1].first.cluster) ++cluster;
            parts_[p].second.cluster = cluster;
            result.parts.push_back(std::move(parts_[p].second));
        }
        std::sort(walls_.begin(), walls_.end(), [](const auto& a, const auto& b) {
            return a.second.inliers != b.second.inliers ? a.second.inliers > b.second.inliers
                                                        : a.first < b.first;
        });
        for (auto& [key, wall] : walls_) {
            wall.id = static_cast<int>(result.walls.size() + 1);
            wall.slant_to_ground_deg = SlantDeg(wall.normal, result.ground.normal);
            result.walls.push_back(std::move(wall));
        }
        parts_.clear();
        walls_.clear();
        return result;
    }

    std::string Release() {
        std::string out = detail::EncodeHandover(stats_, parts_, pieces_, walls_);
        stats_ = {};
        parts_.clear();
        pieces_.clear();
        walls_.clear();
        return out;
    }

    void Absorb(const std::string& bytes) {
        detail::DecodeHandover(bytes, stats_, parts_, pieces_, walls_);
    }

    const core::VoxelMap& map_;
    const openvdb::BoolGrid* observed_free_;  // null: the occupancy says what was seen free
    const WallConfig& config_;
    Eigen::Vector3d up_;
    WallStats stats_;
    double s_;
    double threshold_;
    std::vector<std::pair<PartKey, WallPart>> parts_;
    std::vector<std::pair<PartKey, Piece>> pieces_;  // accepted parts not fitted yet
    std::vector<std::pair<PartKey, Wall>> walls_;    // by their first piece's key
};

WallAssembler::WallAssembler(const core::VoxelMap& map, const WallConfig& config,
                             const Eigen::Vector3d& up, const openvdb::BoolGrid* observed_free) {
    config.Validate();
    if (!map.occupancy) throw InvalidArgumentError("walls: the map has no occupancy grid");
    impl_ = std::make_unique<Impl>(map, config, up, observed_free);
}

WallAssembler::~WallAssembler() = default;

void WallAssembler::Add(const std::vector<std::vector<openvdb::Coord>>& groups) {
    for (const auto& g : groups) impl_->stats_.candidate_voxels += g.size();
    impl_->Add(groups);
}

void WallAssembler::FitSettled(const std::function<bool(const openvdb::CoordBBox&)>& open) {
    impl_->FitSettled(open);
}

std::string WallAssembler::Release() { return impl_->Release(); }

void WallAssembler::Absorb(const std::string& bytes) { impl_->Absorb(bytes); }

size_t WallAssembler::fitted() const { return impl_->walls_.size(); }

std::vector<openvdb::CoordBBox> WallAssembler::PendingBoxes() const {
    return impl_->PendingBoxes();
}

WallResult WallAssembler::Finish(WallResult voted) { return impl_->Finish(std::move(voted)); }

}  // namespace strata::walls
