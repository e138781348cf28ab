// Each stage of the wall pipeline on geometry with a known answer: DBSCAN and K-means on known
// clusters, RANSAC with outliers, the eigenvalue test on a wall and a bush, the slant of a plane
// of known tilt, and the whole pipeline on a hand-made map.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "strata/core/Error.hpp"
#include "strata/geometry/Clustering.hpp"
#include "strata/geometry/PlaneFit.hpp"
#include "strata/walls/Slant.hpp"
#include "strata/walls/WallReport.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::walls {
namespace {

// The geometry module's clusters and plane fits are tested here, on the shapes walls meet.
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

using openvdb::Coord;

constexpr double kDegTol = 1e-9;
constexpr double kRad = M_PI / 180.0;

// Points on the plane through `origin` leaning `lean_deg` towards -y (its top moves to -y),
// spanning `length` in x and `height` in z, with Gaussian noise along the normal.
std::vector<Eigen::Vector3d> WallPoints(double lean_deg, double length, double height, size_t n,
                                        double noise, uint64_t seed,
                                        const Eigen::Vector3d& origin = Eigen::Vector3d::Zero()) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::normal_distribution<double> g(0.0, noise);
    const Eigen::Vector3d up(0.0, -std::sin(lean_deg * kRad), std::cos(lean_deg * kRad));
    const Eigen::Vector3d normal(0.0, std::cos(lean_deg * kRad), std::sin(lean_deg * kRad));
    std::vector<Eigen::Vector3d> out;
    for (size_t i = 0; i < n; ++i) {
        // One draw each, last term first: the operands of + are evaluated in an unspecified
        // order and the points must not depend on the compiler (this is gcc's order).
        const double across = g(rng);
        const double high = u(rng);
        const double along = u(rng);
        out.push_back(origin + Eigen::Vector3d::UnitX() * along * length + up * high * height +
                      normal * across);
    }
    return out;
}

std::vector<Eigen::Vector3d> BushPoints(const Eigen::Vector3d& centre, double radius, size_t n,
                                        uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Eigen::Vector3d> out;
    while (out.size() < n) {
        // z, y, x, one draw each: argument order is unspecified (gcc right to left, clang left to
        // right) and the scan must not depend on the compiler; this is the order gcc always used.
        Eigen::Vector3d d;
        d.z() = u(rng);
        d.y() = u(rng);
        d.x() = u(rng);
        if (d.norm() <= 1.0) out.push_back(centre + radius * d);
    }
    return out;
}

TEST(Dbscan, FindsTwoBlocksAndLeavesIsolatedVoxelsAsNoise) {
    std::vector<Coord> voxels;
    for (int x = 0; x < 5; ++x)
        for (int z = 0; z < 5; ++z) voxels.emplace_back(x, 0, z);  // block A
    for (int x = 20; x < 24; ++x)
        for (int z = 0; z < 4; ++z) voxels.emplace_back(x, 0, z);  // block B, 15 voxels away
    voxels.emplace_back(50, 0, 0);                                 // alone
    voxels.emplace_back(60, 5, 5);                                 // alone
    const std::vector<int> label = Dbscan(voxels, 1.5, 4);
    std::set<int> a(label.begin(), label.begin() + 25), b(label.begin() + 25, label.begin() + 41);
    ASSERT_EQ(a.size(), 1u);
    ASSERT_EQ(b.size(), 1u);
    EXPECT_NE(*a.begin(), *b.begin());
    EXPECT_NE(*a.begin(), kNoise);
    EXPECT_EQ(label[41], kNoise);
    EXPECT_EQ(label[42], kNoise);
    EXPECT_THROW((void)Dbscan(voxels, 0.5, 4), InvalidArgumentError);
}

// Voxels within eps of each other share a group; DBSCAN of each group alone labels its voxels as
// DBSCAN of all of them does (the same partition into clusters and noise).
TEST(ConnectedVoxels, GroupsWhatDbscanCanJoinAndNothingMore) {
    std::vector<Coord> voxels;
    for (int x = 0; x < 6; ++x)
        for (int z = 0; z < 6; ++z) voxels.emplace_back(x, 0, z);  // a block
    for (int x = 8; x < 12; ++x)
        for (int z = 0; z < 6; ++z) voxels.emplace_back(x, 0, z);  // 3 voxels on: another
    voxels.emplace_back(30, 0, 0);                                 // alone
    voxels.emplace_back(5, 0, 7);  // 2 voxels above the first block's corner: joins it
    std::reverse(voxels.begin(), voxels.end());
    const auto groups = geometry::ConnectedVoxels(voxels, 2.0);
    ASSERT_EQ(groups.size(), 3u);
    EXPECT_EQ(groups[0].size(), 37u);
    EXPECT_EQ(groups[1].size(), 24u);
    EXPECT_EQ(groups[2], std::vector<Coord>{Coord(30, 0, 0)});
    for (const auto& g : groups) EXPECT_TRUE(std::is_sorted(g.begin(), g.end()));
    EXPECT_EQ(geometry::ConnectedVoxels(voxels, 3.0).size(), 2u) << "3 voxels apart: joined";

    std::vector<Coord> sorted = voxels;
    std::sort(sorted.begin(), sorted.end());
    const std::vector<int> all = Dbscan(sorted, 2.0, 6);
    size_t at = 0;
    for (const auto& g : groups) {
        const std::vector<int> own = Dbscan(g, 2.0, 6);
        for (size_t n = 0; n < g.size(); ++n) {
            const size_t in_all = static_cast<size_t>(
                std::lower_bound(sorted.begin(), sorted.end(), g[n]) - sorted.begin());
            EXPECT_EQ(own[n] == kNoise, all[in_all] == kNoise) << g[n];
            // Same cluster in the group as its first voxel <=> the same in all.
            const size_t first = static_cast<size_t>(
                std::lower_bound(sorted.begin(), sorted.end(), g[0]) - sorted.begin());
            if (own[n] != kNoise && own[0] != kNoise) {
                EXPECT_EQ(own[n] == own[0], all[in_all] == all[first]) << g[n];
            }
        }
        at += g.size();
    }
    EXPECT_EQ(at, voxels.size());
    EXPECT_THROW((void)geometry::ConnectedVoxels(voxels, 0.5), InvalidArgumentError);
}

// The ground's sample: at most kMaxColumns columns, the same ones and the same plane whatever
// order the columns come in, and every column of a smaller map.
TEST(GroundSample, KeepsTheSameColumnsInAnyOrder) {
    constexpr int kSide = 300;  // 90,000 columns: more than a sample holds
    std::vector<std::pair<int, int>> columns;
    for (int j = 0; j < kSide; ++j)
        for (int i = 0; i < kSide; ++i) columns.emplace_back(i, j);
    // A ground sloping 1 deg up along x.
    const auto lowest = [](int i, int j) {
        return Eigen::Vector3d(0.2 * i, 0.2 * j, 0.2 * i * std::tan(1.0 * kRad));
    };
    GroundSample forward, shuffled, small;
    for (const auto& [i, j] : columns) {
        if (forward.Admits(i, j)) forward.Add(i, j, lowest(i, j));
    }
    std::shuffle(columns.begin(), columns.end(), std::mt19937_64(7));
    for (const auto& [i, j] : columns) shuffled.Add(i, j, lowest(i, j));
    EXPECT_EQ(forward.entries().size(), GroundSample::kMaxColumns);
    EXPECT_EQ(forward.InRasterOrder(), shuffled.InRasterOrder());
    const std::vector<Eigen::Vector3d> sample = forward.InRasterOrder();
    EXPECT_TRUE(std::is_sorted(sample.begin(), sample.end(), [](const auto& a, const auto& b) {
        return a.y() != b.y() ? a.y() < b.y() : a.x() < b.x();
    }));
    // Spread over the map, not bunched: a quarter of the map holds about a quarter.
    const auto in_quarter = std::count_if(sample.begin(), sample.end(), [](const auto& p) {
        return p.x() < 0.2 * kSide / 2 && p.y() < 0.2 * kSide / 2;
    });
    EXPECT_NEAR(static_cast<double>(in_quarter) / sample.size(), 0.25, 0.01);
    EXPECT_NEAR(FitGround(forward, 0.2).tilt_deg, 1.0, 1e-6);
    for (int i = 0; i < 10; ++i) small.Add(i, 0, lowest(i, 0));
    EXPECT_EQ(small.entries().size(), 10u);
}

TEST(KMeans, SeparatesThreeBlobsAndFollowsTheStudysRule) {
    std::vector<Eigen::Vector3d> points;
    const Eigen::Vector3d centres[3] = {{0, 0, 0}, {10, 0, 0}, {0, 10, 5}};
    for (int c = 0; c < 3; ++c) {
        for (const auto& p : BushPoints(centres[c], 1.0, 200, 10 + c)) points.push_back(p);
    }
    const std::vector<int> part = KMeans(points, 3, 5);
    for (int c = 0; c < 3; ++c) {
        const std::set<int> labels(part.begin() + 200 * c, part.begin() + 200 * (c + 1));
        EXPECT_EQ(labels.size(), 1u) << "blob " << c << " was split";
    }
    EXPECT_EQ(std::set<int>(part.begin(), part.end()).size(), 3u);
    EXPECT_EQ(PartsFor(1000, 400), 2);
    EXPECT_EQ(PartsFor(399, 400), 1);
    EXPECT_EQ(PartsFor(1200, 400), 3);
}

TEST(RansacPlane, KeepsThePlaneAndRejectsThirtyPercentOutliers) {
    constexpr double kNoiseM = 0.01, kThreshold = 0.05, kAngleTolDeg = 0.3;
    std::vector<Eigen::Vector3d> points = WallPoints(2.0, 8.0, 4.0, 700, kNoiseM, 1);
    const auto clutter = BushPoints(Eigen::Vector3d(4.0, 1.5, 2.0), 1.2, 300, 2);
    points.insert(points.end(), clutter.begin(), clutter.end());
    const RansacResult r = RansacPlane(points, kThreshold, 200, 3);
    EXPECT_NEAR(SlantDeg(r.plane.normal), 88.0, kAngleTolDeg);
    size_t wall_inliers = 0;
    for (size_t i = 0; i < 700; ++i) wall_inliers += r.inlier[i];
    EXPECT_GE(wall_inliers, 690u);             // all but > 5 sigma of the wall
    EXPECT_LE(r.inliers - wall_inliers, 30u);  // few clutter points happen to lie on the plane
}

TEST(RefinePlane, RobustFitIgnoresARecessedWindow) {
    constexpr double kAngleTolDeg = 0.05;
    std::vector<Eigen::Vector3d> points = WallPoints(3.0, 6.0, 3.0, 2000, 0.005, 4);
    // A window 0.08 m behind the face, only in the upper half: least squares would tilt.
    for (const auto& p : WallPoints(3.0, 2.0, 1.0, 500, 0.005, 5,
                                    Eigen::Vector3d(2.0, -0.08 - 2.0 * std::sin(3.0 * kRad),
                                                    2.0 * std::cos(3.0 * kRad)))) {
        points.push_back(p);
    }
    const PlaneFit ls = FitPlane(points);
    const Plane robust = RefinePlane(points, ls.plane, 0.01);
    EXPECT_GT(std::abs(SlantDeg(ls.plane.normal) - 87.0), 0.2) << "the window should bias LS";
    EXPECT_NEAR(SlantDeg(robust.normal), 87.0, kAngleTolDeg);
}

TEST(WallTests, EigenRatioSeparatesAWallFromABush) {
    const double wall = XyEigenRatio(WallPoints(0.0, 5.0, 3.0, 500, 0.02, 6));
    const double bush = XyEigenRatio(BushPoints(Eigen::Vector3d::Zero(), 0.8, 500, 7));
    EXPECT_GT(wall, 100.0);
    EXPECT_LT(bush, 1.7);  // the study's threshold
}

TEST(Slant, KnownTiltsAndLeanDirections) {
    EXPECT_NEAR(SlantDeg(Eigen::Vector3d(1, 0, 0)), 90.0, kDegTol);
    EXPECT_NEAR(SlantDeg(Eigen::Vector3d(0, 0, 1)), 0.0, kDegTol);
    EXPECT_NEAR(SlantDeg(Eigen::Vector3d(0, 0, -3)), 0.0, kDegTol);
    const Eigen::Vector3d n(std::cos(4.0 * kRad), 0.0, -std::sin(4.0 * kRad));
    EXPECT_NEAR(SlantDeg(n), 86.0, 1e-9);
    EXPECT_NEAR(SlantDeg(-n), 86.0, 1e-9);  // the sign of the normal does not matter
    // Facing +x and looking down: the top leans towards +x (azimuth 0).
    EXPECT_NEAR(LeanAzimuthDeg(n), 0.0, 1e-9);
    // Facing +y and looking up: the top leans away from the front, towards -y (270).
    EXPECT_NEAR(LeanAzimuthDeg(Eigen::Vector3d(0.0, 0.999, 0.04)), 270.0, 1e-9);
    // A fitted plane of known tilt: 87 degrees, with an uncertainty that covers the error.
    const PlaneFit fit = FitPlane(WallPoints(3.0, 10.0, 4.0, 3000, 0.02, 8));
    EXPECT_NEAR(SlantDeg(fit.plane.normal), 87.0, 3.0 * SlantUncertaintyDeg(fit));
    EXPECT_LT(SlantUncertaintyDeg(fit), 0.1);
}

// A hand-made map: ground, a wall 12 m x 5 m leaning 2 deg towards the street (-y) with each
// voxel's mean on the true face, and a bush in front of it.
core::VoxelMap HandMadeStreet(double voxel) {
    core::VoxelMap map = core::VoxelMap::Create(voxel);
    auto occ = map.occupancy->getAccessor();
    const auto put = [&](const Eigen::Vector3d& p) {
        const Coord c = map.WorldToVoxel(p);
        const Eigen::Vector3d offset = p - map.VoxelCenter(c);
        occ.setValueOn(c, 1.0f);
        map.SetEndpoints(c, 1, offset);
    };
    for (double x = -5.0; x < 20.0; x += voxel) {
        for (double y = -8.0; y < 6.0; y += voxel) put({x + 0.3 * voxel, y + 0.3 * voxel, 0.01});
    }
    // Wall face through y = 5 at z = 0; the top at z = 5 sits 5 tan(2 deg) nearer the street.
    for (double x = 0.0; x < 12.0; x += voxel / 2) {
        for (double z = 0.0; z < 5.0; z += voxel / 2) put({x, 5.0 - z * std::tan(2.0 * kRad), z});
    }
    for (const auto& p : BushPoints(Eigen::Vector3d(15.0, 3.0, 1.0), 0.9, 4000, 9)) put(p);
    // The scanner drove along the street (y < 4.5): what it saw there and did not hit is free.
    const Coord lo = map.WorldToVoxel({-5.0, -8.0, 0.3}), hi = map.WorldToVoxel({20.0, 4.5, 5.0});
    for (auto it = openvdb::CoordBBox(lo, hi).begin(); it; ++it) {
        if (!occ.isValueOn(*it)) occ.setValueOn(*it, -1.0f);
    }
    return map;
}

TEST(FindWalls, MeasuresTheSlantOfAHandMadeWallAndLeavesTheBush) {
    constexpr double kSlantTolDeg = 0.05;
    const core::VoxelMap map = HandMadeStreet(0.2);
    const WallResult result = FindWalls(map);
    ASSERT_EQ(result.walls.size(), 1u);
    const Wall& w = result.walls[0];
    EXPECT_NEAR(w.slant_deg, 88.0, kSlantTolDeg);
    EXPECT_LT(w.normal.y(), 0.0) << "the normal points to the free side, the street";
    EXPECT_NEAR(w.lean_azimuth_deg, 270.0, 1.0);  // leans towards -y
    EXPECT_NEAR(w.length_m, 12.0, 0.5);
    EXPECT_GT(w.height_m, 4.0);
    EXPECT_NEAR(w.area_m2, w.length_m * w.height_m, 0.15 * w.length_m * w.height_m);
    for (const WallPart& p : result.parts) {
        if ((p.centroid - Eigen::Vector3d(15.0, 3.0, 1.0)).norm() < 1.5) {
            EXPECT_NE(p.verdict, PartVerdict::kWall) << "the bush was taken for a wall";
        }
    }
    // Products: one slant and one id per inlier voxel.
    const openvdb::GridPtrVec grids = WallGrids(result);
    ASSERT_EQ(grids.size(), 2u);
    EXPECT_EQ(grids[0]->activeVoxelCount(), w.voxels.size());
    const std::string json = WallsJson(result, {}, Eigen::Vector3d::Zero());
    for (const char* key :
         {"\"slant_deg\"", "\"centroid\"", "\"normal\"", "\"inliers\"", "\"area_m2\"", "\"rms_m\"",
          "\"uncertainty_deg\"", "\"lean_azimuth_deg\""}) {
        EXPECT_NE(json.find(key), std::string::npos) << key;
    }
}

TEST(FindWalls, EstimatesTheGroundTiltAndCanMeasureAgainstIt) {
    constexpr double kTiltTolDeg = 0.05;
    // The hand-made street, seen in a frame rolled by 1.5 deg about x (an unlevelled odometry
    // frame): ground and wall tilt together.
    const core::VoxelMap level = HandMadeStreet(0.2);
    core::VoxelMap rolled = core::VoxelMap::Create(0.2);
    const Eigen::Matrix3d roll = Eigen::AngleAxisd(1.5 * kRad, Eigen::Vector3d::UnitX()).matrix();
    auto occ = rolled.occupancy->getAccessor();
    for (auto it = level.occupancy->cbeginValueOn(); it; ++it) {
        const Eigen::Vector3d p = roll * level.PointMean(it.getCoord());
        const Coord c = rolled.WorldToVoxel(p);
        if (*it <= 0.0f) {
            if (!occ.isValueOn(c)) occ.setValueOn(c, *it);
            continue;
        }
        const Eigen::Vector3d offset = p - rolled.VoxelCenter(c);
        occ.setValueOn(c, 1.0f);
        rolled.SetEndpoints(c, 1, offset);
    }
    const columns::ColumnGrid cols = columns::ColumnGrid::FromMap(rolled);
    EXPECT_NEAR(EstimateGround(rolled, cols).tilt_deg, 1.5, kTiltTolDeg);
    EXPECT_NEAR(EstimateGround(level, columns::ColumnGrid::FromMap(level)).tilt_deg, 0.0,
                kTiltTolDeg);
    // The wall leans 2 deg towards -y; rolling by +1.5 deg about x turns it further, to 3.5.
    const WallResult in_map = FindWalls(rolled);
    ASSERT_EQ(in_map.walls.size(), 1u);
    EXPECT_NEAR(in_map.walls[0].slant_deg, 86.5, 0.1);
    EXPECT_NEAR(in_map.walls[0].slant_to_ground_deg, 88.0, 0.1);
    WallConfig levelled;
    levelled.level_to_ground = true;
    const WallResult against_ground = FindWalls(rolled, levelled);
    ASSERT_EQ(against_ground.walls.size(), 1u);
    EXPECT_NEAR(against_ground.walls[0].slant_deg, 88.0, 0.1);
}

TEST(FindWalls, RejectsABadConfig) {
    const core::VoxelMap map = core::VoxelMap::Create(0.2);
    WallConfig c;
    c.window_m = 0.0;
    EXPECT_THROW((void)FindWalls(map, c), InvalidArgumentError);
    c = {};
    c.kmeans_divisor = 0;
    EXPECT_THROW((void)FindWalls(map, c), InvalidArgumentError);
    EXPECT_TRUE(FindWalls(map).walls.empty());  // an empty map has no walls, and no error
}

}  // namespace
}  // namespace strata::walls
