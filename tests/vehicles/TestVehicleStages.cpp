// Each stage of the vehicle pipeline on geometry with a known answer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/vehicles/VehicleStages.hpp"

namespace strata::vehicles {
namespace {

using core::SemanticClass;
constexpr double kPi = 3.14159265358979323846;
constexpr double kVoxel = 0.1;
constexpr double kYawToleranceDeg = 1.0;
constexpr double kSideToleranceM = 0.1;
constexpr double kRefillHeightToleranceM = 0.01;

// A map with helpers to write occupied or free voxels at a point.
struct TestMap {
    core::VoxelMap map = core::VoxelMap::Create(kVoxel);

    void Occupy(const Eigen::Vector3d& p, SemanticClass c) {
        const openvdb::Coord ijk = map.WorldToVoxel(p);
        map.occupancy->tree().setValue(ijk, 2.0F);
        map.label->tree().setValue(ijk, static_cast<int32_t>(c));
        map.label_weight->tree().setValue(ijk, 1.0F);
        map.SetEndpoints(ijk, 1, p - map.VoxelCenter(ijk));
    }
    void Free(const Eigen::Vector3d& p) {
        map.occupancy->tree().setValue(map.WorldToVoxel(p), -2.0F);
    }
    [[nodiscard]] bool Occupied(const Eigen::Vector3d& p) const {
        return map.occupancy->tree().getValue(map.WorldToVoxel(p)) > 0.0F;
    }
    // Ground z = slope * x over [x0, x1] x [y0, y1], one point per column.
    void Ground(double x0, double x1, double y0, double y1, double slope, SemanticClass c) {
        for (double x = x0 + 0.05; x < x1; x += kVoxel) {
            for (double y = y0 + 0.05; y < y1; y += kVoxel) Occupy({x, y, 0.02 + slope * x}, c);
        }
    }
    // The shell of an axis-aligned car body [x0, x1] x [y0, y1] x [z0, z1] (sides and roof).
    void Body(double x0, double x1, double y0, double y1, double z0, double z1, SemanticClass c) {
        for (double x = x0 + 0.05; x < x1; x += kVoxel) {
            for (double y = y0 + 0.05; y < y1; y += kVoxel) {
                for (double z = z0 + 0.05; z < z1; z += kVoxel) {
                    const bool side = x < x0 + kVoxel || x > x1 - kVoxel || y < y0 + kVoxel ||
                                      y > y1 - kVoxel || z > z1 - kVoxel;
                    if (side) Occupy({x, y, z}, c);
                }
            }
        }
    }
};

TEST(LShapeFit, RecoversTheHeadingAndSidesOfAKnownL) {
    // Two sides of a 4.5 m x 1.8 m rectangle at 30 degrees, 2 cm noise, as a scanner sees a car.
    const double yaw = 30.0 * kPi / 180.0;
    const Eigen::Vector2d a(std::cos(yaw), std::sin(yaw)), b(-a.y(), a.x());
    const Eigen::Vector2d corner(3.0, -2.0);
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 0.02);
    std::vector<Eigen::Vector2d> points;
    for (double t = 0.0; t <= 4.5; t += 0.05) points.push_back(corner + t * a + noise(rng) * b);
    for (double t = 0.05; t <= 1.8; t += 0.05) points.push_back(corner + t * b + noise(rng) * a);
    const OrientedRect r = FitLShape(points);
    EXPECT_NEAR(r.yaw_rad * 180.0 / kPi, 30.0, kYawToleranceDeg);
    EXPECT_NEAR(r.length, 4.5, kSideToleranceM);
    EXPECT_NEAR(r.width, 1.8, kSideToleranceM);
    EXPECT_LT((r.center - (corner + 2.25 * a + 0.9 * b)).norm(), kSideToleranceM);
    EXPECT_THROW((void)FitLShape({Eigen::Vector2d::Zero()}), InvalidArgumentError);
}

TEST(LShapeFit, BirdsEyeIoUOfKnownRectangles) {
    OrientedRect a;
    a.length = 4.0, a.width = 2.0;
    OrientedRect b = a;
    EXPECT_NEAR(BirdsEyeIoU(a, b), 1.0, 1e-12);
    b.center = {2.0, 0.0};  // half overlaps: 4 / (8 + 8 - 4)
    EXPECT_NEAR(BirdsEyeIoU(a, b), 4.0 / 12.0, 1e-12);
    b.center = {0.0, 0.0}, b.yaw_rad = kPi / 2;  // a cross: the 2 x 2 middle
    EXPECT_NEAR(OverlapArea(a, b), 4.0, 1e-12);
    b.center = {10.0, 0.0};
    EXPECT_EQ(OverlapArea(a, b), 0.0);
}

TEST(LShapeFit, AFrontSeenFromTheAisleGrowsIntoACarAwayFromTheViewer) {
    // Only the 1.8 m front at y = 0 was seen, from an aisle at y = -5: the car is y in [0, 4.5].
    OrientedRect seen;
    seen.center = {0.0, 0.05};
    seen.length = 1.8;
    seen.width = 0.1;
    seen.yaw_rad = 0.0;
    const OrientedRect car = ExtendToCarSize(seen, {0.0, -5.0});
    EXPECT_NEAR(car.length, 4.5, 1e-9);
    EXPECT_NEAR(car.width, 1.8, 1e-9);
    EXPECT_NEAR(std::abs(car.yaw_rad), kPi / 2, 1e-9);
    EXPECT_NEAR(car.center.y(), 2.25, 1e-9);  // the seen front edge, y = 0, stays
}

TEST(RefillGround, FollowsTheSlopeOfTheRingNotOneMeanHeight) {
    TestMap t;
    constexpr double kSlope = 0.1;  // a 10 % ramp along x
    t.Ground(-6.0, 6.0, -6.0, 6.0, kSlope, SemanticClass::kGround);
    Vehicle car;
    car.footprint.center = {0.0, 0.0};
    car.footprint.length = 4.0;
    car.footprint.width = 2.0;
    car.ground_z = 0.0;
    car.height = 1.5;
    // The vehicle stood here: its ground is unknown (cleared before the refill).
    for (double x = -2.0 + 0.05; x < 2.0; x += kVoxel) {
        for (double y = -1.0 + 0.05; y < 1.0; y += kVoxel) {
            const openvdb::Coord c = t.map.WorldToVoxel({x, y, 0.02 + kSlope * x});
            t.map.occupancy->tree().setValueOff(c, 0.0F);
        }
    }
    const GroundField ground = GroundField::FromMap(t.map, {});
    auto refilled = openvdb::FloatGrid::create(0.0F);
    RefillGround(t.map, car, ground, nullptr, *refilled, {});
    EXPECT_EQ(car.refilled_cells, 40U * 20U);
    EXPECT_EQ(car.refused_cells, 0U);
    EXPECT_NEAR(car.ground_plane[1], kSlope, 0.005);
    for (auto it = refilled->cbeginValueOn(); it; ++it) {
        const Eigen::Vector3d c = t.map.VoxelCenter(it.getCoord());
        ASSERT_NEAR(*it, 0.02 + kSlope * c.x(), kRefillHeightToleranceM) << "at x " << c.x();
        // The refilled height becomes the voxel's point mean, to half a level of its packing.
        ASSERT_NEAR(t.map.PointMean(it.getCoord()).z(), *it,
                    kVoxel / (2.0 * core::endpoint::kLevels) * 1.0001);
        ASSERT_EQ(t.map.label->tree().getValue(it.getCoord()),
                  static_cast<int32_t>(SemanticClass::kGround));
    }
}

TEST(RayCheck, AVisibleGapSeenEmptyStaysEmptyWhileCellsTheCarHidFill) {
    // Flat ground; a drain across x in [0.0, 1.5], seen empty everywhere, also under the car.
    // The car body (0.3 m above the ground) covers x in [-2, 1.2], its box reaches x = 2; the
    // sensor stands at x = 6. Drain cells the body hides from the sensor are filled; visible
    // ones (in front of the body, or seen under its sill) are refused.
    TestMap t;
    t.Ground(-8.0, 8.0, -6.0, 6.0, 0.0, SemanticClass::kGround);
    for (double x = 0.05; x < 1.5; x += kVoxel) {
        for (double y = -5.95; y < 6.0; y += kVoxel) {
            t.map.occupancy->tree().setValueOff(t.map.WorldToVoxel({x, y, 0.02}), 0.0F);
            t.Free({x, y, 0.02});
            t.Occupy({x, y, -0.8}, SemanticClass::kGround);  // the drain's bottom
        }
    }
    t.Body(-2.0, 1.2, -0.9, 0.9, 0.3, 1.5, SemanticClass::kVehicle);
    const std::vector<Eigen::Vector3d> origins = {{6.0, 0.0, 1.7}};
    const GroundField ground = GroundField::FromMap(t.map, {});
    VehicleConfig config;
    Eigen::AlignedBox3d region(Eigen::Vector3d(-20, -20, -5), Eigen::Vector3d(20, 20, 5));
    const RayCheck check(t.map, ground, origins, region, config);
    EXPECT_GT(check.faces(), 0U);
    EXPECT_TRUE(check.Visible({1.25, 0.0, 0.02}));   // drain in front of the body
    EXPECT_FALSE(check.Visible({-1.0, 0.0, 0.02}));  // under the body

    // Remove the body as clearing would, then refill the box x in [-2, 2].
    for (auto it = t.map.label->cbeginValueOn(); it; ++it) {
        if (*it == static_cast<int32_t>(SemanticClass::kVehicle)) {
            t.map.occupancy->tree().setValueOff(it.getCoord(), 0.0F);
        }
    }
    Vehicle car;
    car.footprint.center = {0.0, 0.0};
    car.footprint.length = 4.0;
    car.footprint.width = 1.8;
    car.height = 1.5;
    auto refilled = openvdb::FloatGrid::create(0.0F);
    RefillGround(t.map, car, ground, &check, *refilled, config);
    EXPECT_GT(car.refused_cells, 0U);
    EXPECT_FALSE(t.Occupied({1.45, 0.0, 0.02})) << "the visible drain was filled";
    EXPECT_FALSE(t.Occupied({1.05, 0.0, 0.02})) << "the drain seen under the sill was filled";
    EXPECT_TRUE(t.Occupied({0.05, 0.0, 0.02})) << "the drain under the body stayed open";
}

TEST(ClearVehicles, ALabelledCarIsClearedAndItsGroundRefilled) {
    TestMap t;
    t.Ground(-8.0, 8.0, -6.0, 6.0, 0.0, SemanticClass::kGround);
    t.Body(-2.2, 2.2, -0.9, 0.9, 0.3, 1.5, SemanticClass::kVehicle);
    // The ground under the car was never seen.
    for (double x = -2.15; x < 2.2; x += kVoxel) {
        for (double y = -0.85; y < 0.9; y += kVoxel) {
            t.map.occupancy->tree().setValueOff(t.map.WorldToVoxel({x, y, 0.02}), 0.0F);
        }
    }
    const std::vector<Eigen::Vector3d> origins = {{0.0, -6.0, 1.7}, {5.0, -6.0, 1.7}};
    const VehicleResult r = ClearVehicles(t.map, origins);
    EXPECT_EQ(r.source, VehicleSource::kLabel);
    ASSERT_EQ(r.vehicles.size(), 1U);
    const Vehicle& v = r.vehicles[0];
    EXPECT_EQ(v.source, VehicleSource::kLabel);
    EXPECT_LT((v.footprint.center - Eigen::Vector2d(0.0, 0.0)).norm(), kSideToleranceM);
    EXPECT_NEAR(v.footprint.length, 4.4, 2 * kSideToleranceM);
    EXPECT_NEAR(v.footprint.width, 1.8, 2 * kSideToleranceM);
    EXPECT_GT(v.cleared_voxels, 0U);
    for (auto it = t.map.label->cbeginValueOn(); it; ++it) {
        ASSERT_NE(*it, static_cast<int32_t>(SemanticClass::kVehicle)) << it.getCoord();
    }
    EXPECT_EQ(v.refilled_cells, 44U * 18U);
    EXPECT_TRUE(t.Occupied({0.0, 0.0, 0.02}));
    EXPECT_EQ(r.cleared->activeVoxelCount(), v.cleared_voxels);
}

// What the windows of a map answer together, as the tile-by-tile pipeline drives them: every
// window once with its long objects kept, the long objects joined from their samples, the
// windows their vehicles reach again with them; vehicles in key order.
struct Windowed {
    std::vector<std::pair<CarKey, Vehicle>> cars;
    std::set<openvdb::Coord> cleared;
    size_t candidates = 0, long_objects = 0, repeated = 0;
};
Windowed ClearInWindows(const core::VoxelMap& map, const GroundField& ground,
                        const std::vector<Eigen::Vector3d>& origins,
                        const std::vector<openvdb::CoordBBox>& cores, VehicleSource source,
                        const VehicleConfig& config) {
    std::vector<Window> windows;
    std::vector<WindowVehicles> found;
    std::vector<ObjectSample> samples;
    for (const openvdb::CoordBBox& c : cores) {
        windows.push_back(WindowAround(c, map.voxel_size, config));
        core::VoxelMap copy = map.DeepCopy();
        found.push_back(
            ClearVehiclesInWindow(copy, ground, origins, windows.back(), source, config));
        samples.insert(samples.end(), found.back().long_samples.begin(),
                       found.back().long_samples.end());
    }
    const LongObjects long_objects =
        FitLongObjects(samples, map.voxel_size, source, origins, config);
    Windowed out;
    out.long_objects = long_objects.objects;
    for (size_t w = 0; w < windows.size(); ++w) {
        if (!LongVehiclesReach(long_objects, windows[w], map.voxel_size, config)) continue;
        core::VoxelMap copy = map.DeepCopy();
        found[w] =
            ClearVehiclesInWindow(copy, ground, origins, windows[w], source, config, &long_objects);
        ++out.repeated;
    }
    for (const WindowVehicles& f : found) {
        out.cars.insert(out.cars.end(), f.vehicles.begin(), f.vehicles.end());
        for (const auto& [c, key] : f.cleared) out.cleared.insert(c);
        out.candidates += f.candidates;
    }
    out.candidates += long_objects.objects;
    std::sort(out.cars.begin(), out.cars.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    return out;
}

// A row of eight touching cars, 35 m long, is one object, longer than a window with a 20 m ray
// range is sure to see whole (9.1 m); a lone car beyond it is not. Read in two windows, the row
// is joined from their samples and its cars are cleared by the windows they reach, each car
// reported by the window whose core holds its own first voxel: the whole map's cars and cleared
// voxels.
TEST(ClearVehiclesInWindow, ARowOfCarsLongerThanAWindowSeesIsJoinedAcrossWindows) {
    TestMap t;
    t.Ground(-2.0, 58.0, -6.0, 6.0, 0.0, SemanticClass::kGround);
    constexpr int kCars = 8;
    constexpr double kCarM = 4.4;
    for (int k = 0; k < kCars; ++k) {
        t.Body(k * kCarM, (k + 1) * kCarM, -0.9, 0.9, 0.3, 1.5, SemanticClass::kVehicle);
    }
    t.Body(45.0, 49.4, -0.9, 0.9, 0.3, 1.5, SemanticClass::kVehicle);
    std::vector<Eigen::Vector3d> origins;
    for (double x = 0.0; x <= 50.0; x += 5.0) origins.emplace_back(x, -5.0, 1.7);
    VehicleConfig config;
    config.ray_range_m = 20.0;
    core::VoxelMap whole_map = t.map.DeepCopy();
    const VehicleResult whole = ClearVehicles(whole_map, origins, config);
    ASSERT_GE(whole.vehicles.size(), 6U);
    ASSERT_EQ(whole.candidates, 2U);

    GroundConfig ground_config = config.ground;
    ground_config.use_labels = true;
    const GroundField ground = GroundField::FromMap(t.map, ground_config);
    // Columns in voxels; the row runs over x in [0, 352), the lone car over [450, 494).
    const auto columns = [](int x0, int x1) {
        return openvdb::CoordBBox(openvdb::Coord(x0, -60, 0), openvdb::Coord(x1, 59, 0));
    };
    const int long_voxels = WindowAround(columns(0, 0), kVoxel, config).long_voxels;
    ASSERT_LT(long_voxels, 352);
    ASSERT_GT(long_voxels, 44);
    const Windowed windowed =
        ClearInWindows(t.map, ground, origins, {columns(-100, 99), columns(100, 600)},
                       VehicleSource::kLabel, config);
    EXPECT_EQ(windowed.long_objects, 1U);
    EXPECT_EQ(windowed.repeated, 2U);
    EXPECT_EQ(windowed.candidates, whole.candidates);
    ASSERT_EQ(windowed.cars.size(), whole.vehicles.size());
    for (size_t n = 0; n < windowed.cars.size(); ++n) {
        const Vehicle &a = windowed.cars[n].second, &b = whole.vehicles[n];
        EXPECT_EQ(a.footprint.center, b.footprint.center) << n;
        EXPECT_EQ(a.footprint.yaw_rad, b.footprint.yaw_rad) << n;
        EXPECT_EQ(a.ground_z, b.ground_z) << n;
        EXPECT_EQ(a.height, b.height) << n;
        EXPECT_EQ(a.cleared_voxels, b.cleared_voxels) << n;
        EXPECT_EQ(a.refilled_cells, b.refilled_cells) << n;
    }
    std::set<openvdb::Coord> whole_cleared;
    for (auto it = whole.cleared->cbeginValueOn(); it; ++it) whole_cleared.insert(it.getCoord());
    EXPECT_EQ(windowed.cleared, whole_cleared);
}

}  // namespace
}  // namespace strata::vehicles
