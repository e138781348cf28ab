// Change detection on hand-made masks whose answer is known voxel by voxel.
#include <gtest/gtest.h>

#include <cmath>

#include "strata/change/ChangeDetection.hpp"
#include "strata/core/Error.hpp"

namespace strata::change {
namespace {

using openvdb::BoolGrid;
using openvdb::Coord;
using openvdb::CoordBBox;

constexpr double kVoxel = 0.2;

BoolGrid::Ptr Mask(std::initializer_list<CoordBBox> boxes) {
    BoolGrid::Ptr grid = BoolGrid::create(false);
    for (const CoordBBox& b : boxes) {
        for (auto it = b.begin(); it; ++it) grid->tree().setValueOn(*it, true);
    }
    return grid;
}

Observation Side(BoolGrid::Ptr occupied, BoolGrid::Ptr free) {
    free->topologyDifference(*occupied);  // the two masks of a side are disjoint
    return Observation{{std::move(occupied), std::move(free)}, nullptr};
}

size_t Count(const CoordBBox& b) { return static_cast<size_t>(b.volume()); }

// A street seen twice: a car leaves, a box arrives, and a wall appears where "before" never saw.
// Both stand on a road (z = 0) that both sides saw.
struct Street {
    CoordBBox world{Coord(0, 0, 0), Coord(99, 29, 9)};
    CoordBBox road{Coord(0, 0, 0), Coord(99, 29, 0)};
    CoordBBox car{Coord(10, 10, 1), Coord(19, 14, 5)};    // 250 voxels, in A only
    CoordBBox box{Coord(40, 10, 1), Coord(44, 14, 5)};    // 125 voxels, in B only
    CoordBBox shadow{Coord(80, 0, 0), Coord(99, 29, 9)};  // A never saw it
    CoordBBox wall{Coord(90, 0, 1), Coord(90, 29, 9)};    // B sees it occupied
    Observation a, b;

    Street() {
        const CoordBBox seen_by_a(world.min(), Coord(79, 29, 9));
        a = Side(Mask({car, {road.min(), Coord(79, 29, 0)}}), Mask({seen_by_a}));
        b = Side(Mask({box, wall, road}), Mask({world}));
    }
};

TEST(ChangeDetection, AddedRemovedAndUnknownFollowTheDefinitions) {
    const Street s;
    ChangeQuery query;
    query.min_voxels = 1;
    const ChangeSet changes = DetectChanges(s.a, s.b, kVoxel, query);
    EXPECT_EQ(changes.added_voxels_total, Count(s.box));
    EXPECT_EQ(changes.removed_voxels_total, Count(s.car));
    // Seen only by B: the whole shadow (the wall in it included), never a change.
    EXPECT_EQ(changes.unknown_voxels, Count(s.shadow));
    ASSERT_EQ(changes.objects.size(), 2u);
    EXPECT_EQ(changes.objects[0].kind, ChangeKind::kRemoved);  // largest first
    EXPECT_EQ(changes.objects[0].voxels, Count(s.car));
    EXPECT_EQ(changes.objects[1].kind, ChangeKind::kAdded);
    EXPECT_EQ(changes.objects[0].id, 1);
    EXPECT_EQ(changes.objects[1].id, 2);
    for (auto on = changes.added->cbeginValueOn(); on; ++on) {
        EXPECT_TRUE(s.box.isInside(on.getCoord()));
    }
    EXPECT_EQ(changes.added->activeVoxelCount(), Count(s.box));
    EXPECT_EQ(changes.removed->activeVoxelCount(), Count(s.car));
}

TEST(ChangeDetection, SwappedSidesSwapAddedAndRemoved) {
    const Street s;
    const ChangeSet forward = DetectChanges(s.a, s.b, kVoxel);
    const ChangeSet backward = DetectChanges(s.b, s.a, kVoxel);
    EXPECT_EQ(forward.added_voxels_total, backward.removed_voxels_total);
    EXPECT_EQ(forward.removed_voxels_total, backward.added_voxels_total);
    EXPECT_EQ(forward.unknown_voxels, backward.unknown_voxels);
}

TEST(ChangeDetection, ObjectStatisticsOfABox) {
    const Street s;
    const ChangeSet changes = DetectChanges(s.a, s.b, kVoxel);
    const ChangeObject& car = changes.objects[0];
    constexpr double kTol = 1e-9;
    EXPECT_NEAR(car.volume_m3, 250 * kVoxel * kVoxel * kVoxel, kTol);
    EXPECT_TRUE(car.bbox_min.isApprox(Eigen::Vector3d(2.0, 2.0, 0.2), kTol));
    EXPECT_TRUE(car.bbox_max.isApprox(Eigen::Vector3d(4.0, 3.0, 1.2), kTol));
    EXPECT_TRUE(car.centroid.isApprox(Eigen::Vector3d(3.0, 2.5, 0.7), kTol));
    EXPECT_NEAR(std::abs(car.oriented.yaw_deg), 0.0, 1e-6);
    EXPECT_TRUE(car.oriented.size.isApprox(Eigen::Vector3d(2.0, 1.0, 1.0), kTol));
    EXPECT_EQ(car.dominant_class, core::SemanticClass::kUnknown);  // no labels given
}

TEST(ChangeDetection, OrientedBoxFollowsATurnedObject) {
    // A 4 m x 1.6 m slab turned by 30 degrees, rasterised at 0.1 m.
    constexpr double kYaw = 30.0, kLength = 4.0, kWidth = 1.6, s = 0.1;
    const double c = std::cos(kYaw * M_PI / 180.0), n = std::sin(kYaw * M_PI / 180.0);
    BoolGrid::Ptr mask = BoolGrid::create(false);
    for (int i = -40; i <= 40; ++i) {
        for (int j = -40; j <= 40; ++j) {
            const double x = (i + 0.5) * s, y = (j + 0.5) * s;
            const double u = c * x + n * y, v = -n * x + c * y;
            if (std::abs(u) <= kLength / 2 && std::abs(v) <= kWidth / 2) {
                for (int k = 0; k < 3; ++k) mask->tree().setValueOn(Coord(i, j, k), true);
            }
        }
    }
    const auto objects = GroupObjects(*mask, ChangeKind::kAdded, s, 0, nullptr);
    ASSERT_EQ(objects.size(), 1u);
    const OrientedBox& box = objects[0].object.oriented;
    constexpr double kYawTolDeg = 1.0, kSizeTol = 2 * s;
    EXPECT_NEAR(box.yaw_deg, kYaw, kYawTolDeg);
    EXPECT_NEAR(box.size.x(), kLength, kSizeTol);
    EXPECT_NEAR(box.size.y(), kWidth, kSizeTol);
    EXPECT_NEAR(box.size.z(), 3 * s, 1e-9);
    EXPECT_LT(box.center.head<2>().norm(), s);
}

TEST(ChangeDetection, GapToleranceJoinsNearbyVoxels) {
    // Two blocks one empty voxel apart, and a third three voxels away.
    BoolGrid::Ptr mask = Mask({{Coord(0, 0, 0), Coord(2, 2, 2)},
                               {Coord(4, 0, 0), Coord(6, 2, 2)},
                               {Coord(10, 0, 0), Coord(12, 2, 2)}});
    EXPECT_EQ(GroupObjects(*mask, ChangeKind::kAdded, kVoxel, 0, nullptr).size(), 3u);
    EXPECT_EQ(GroupObjects(*mask, ChangeKind::kAdded, kVoxel, 1, nullptr).size(), 2u);
    EXPECT_EQ(GroupObjects(*mask, ChangeKind::kAdded, kVoxel, 3, nullptr).size(), 1u);
    // Diagonal neighbours touch at gap 0 (26-connectivity).
    BoolGrid::Ptr diagonal =
        Mask({{Coord(0, 0, 0), Coord(0, 0, 0)}, {Coord(1, 1, 1), Coord(1, 1, 1)}});
    EXPECT_EQ(GroupObjects(*diagonal, ChangeKind::kAdded, kVoxel, 0, nullptr).size(), 1u);
}

TEST(ChangeDetection, MinimumSizeDropsSpeckles) {
    Street s;
    s.b.masks.occupied->tree().setValueOn(Coord(60, 20, 3), true);  // one speckle, seen free by A
    s.b.masks.free->tree().setValueOff(Coord(60, 20, 3));
    ChangeQuery query;
    query.min_voxels = 2;
    const ChangeSet changes = DetectChanges(s.a, s.b, kVoxel, query);
    EXPECT_EQ(changes.objects.size(), 2u);
    EXPECT_EQ(changes.added_voxels_total, Count(s.box));  // too small to seed an object
    EXPECT_EQ(changes.added->activeVoxelCount(), Count(s.box));

    // Without growth the speck is a change (but still no object), and the box loses its bottom
    // layer: it lies within the surface tolerance of A's road.
    query.grow_voxels = 0;
    query.surface_tolerance_voxels = 1;
    const ChangeSet plain = DetectChanges(s.a, s.b, kVoxel, query);
    const size_t bottom_layer = 5 * 5;
    EXPECT_EQ(plain.objects.size(), 2u);
    EXPECT_EQ(plain.added_voxels_total, Count(s.box) - bottom_layer + 1);
    EXPECT_EQ(plain.added->activeVoxelCount(), Count(s.box) - bottom_layer);  // objects only
}

TEST(ChangeDetection, SafeguardsAndGrowthAtASurface) {
    // B sees a 3 x 3 x 3 block standing on a floor A saw; the floor's last voxel row under the
    // block is within the surface tolerance of A's floor and is restored by growth.
    const CoordBBox floor(Coord(0, 0, 0), Coord(19, 19, 0));
    const CoordBBox block(Coord(8, 8, 1), Coord(10, 10, 3));
    const CoordBBox space(Coord(0, 0, 1), Coord(19, 19, 8));
    const Observation a = Side(Mask({floor}), Mask({floor, space}));
    const Observation b = Side(Mask({floor, block}), Mask({floor, space}));
    ChangeQuery query;
    query.min_voxels = 1;
    query.surface_tolerance_voxels = 1;
    query.grow_voxels = 0;
    // Layer z = 1 touches A's floor: dropped by the tolerance. z = 2 and 3 remain.
    EXPECT_EQ(DetectChanges(a, b, kVoxel, query).added_voxels_total, 18u);
    query.grow_voxels = 1;
    EXPECT_EQ(DetectChanges(a, b, kVoxel, query).added_voxels_total, Count(block));
    query.surface_tolerance_voxels = 0;
    query.grow_voxels = 0;
    EXPECT_EQ(DetectChanges(a, b, kVoxel, query).added_voxels_total, Count(block));
}

TEST(ChangeDetection, AFloorSeenOnlyFromAboveIsNotRemoved) {
    // A saw a two-voxel-thick floor occupied; B's grazing rays crossed both layers (free) but
    // nothing under them, so B never saw what is below: the floor did not go anywhere.
    const CoordBBox floor(Coord(0, 0, 0), Coord(19, 19, 1));
    const CoordBBox space(Coord(0, 0, 2), Coord(19, 19, 8));
    const Observation a = Side(Mask({floor}), Mask({floor, space}));
    const Observation b = Side(Mask({}), Mask({floor, space}));
    ChangeQuery query;
    query.min_voxels = 1;
    query.observed_margin_voxels = 0;  // this test is about the support rule alone
    EXPECT_EQ(DetectChanges(a, b, kVoxel, query).removed_voxels_total, 0u);
    query.support_depth_voxels = 0;
    EXPECT_GT(DetectChanges(a, b, kVoxel, query).removed_voxels_total, 0u);
}

TEST(ChangeDetection, RegionRestrictsEverything) {
    const Street s;
    ChangeQuery query;
    query.region = core::Region::Box(7.0, 0.0, 12.0, 6.0);  // around the new box (x 8-9 m)
    const ChangeSet changes = DetectChanges(s.a, s.b, kVoxel, query);
    ASSERT_EQ(changes.objects.size(), 1u);
    EXPECT_EQ(changes.objects[0].kind, ChangeKind::kAdded);
    EXPECT_EQ(changes.removed_voxels_total, 0u);
    EXPECT_EQ(changes.unknown_voxels, 0u);

    // A triangle holding the car's centre column but not the box.
    query.region = core::Region::Polygon({{0.0, 0.0}, {6.0, 0.0}, {0.0, 6.0}});
    const ChangeSet tri = DetectChanges(s.a, s.b, kVoxel, query);
    ASSERT_EQ(tri.objects.size(), 1u);
    EXPECT_EQ(tri.objects[0].kind, ChangeKind::kRemoved);
    for (auto on = tri.removed->cbeginValueOn(); on; ++on) {
        const Coord c = on.getCoord();
        EXPECT_LT((c.x() + 0.5) * kVoxel + (c.y() + 0.5) * kVoxel, 6.0 + 1e-9);
    }
}

TEST(ChangeDetection, ClassFilterUsesTheSideThatSawTheObject) {
    Street s;
    auto labels_a = openvdb::Int32Grid::create(0);
    for (auto it = s.car.begin(); it; ++it) {
        labels_a->tree().setValue(*it, static_cast<int>(core::SemanticClass::kVehicle));
    }
    s.a.labels = labels_a;
    ChangeQuery query;
    query.class_filter = core::SemanticClass::kVehicle;
    const ChangeSet changes = DetectChanges(s.a, s.b, kVoxel, query);
    ASSERT_EQ(changes.objects.size(), 1u);
    EXPECT_EQ(changes.objects[0].kind, ChangeKind::kRemoved);
    EXPECT_EQ(changes.objects[0].dominant_class, core::SemanticClass::kVehicle);
    EXPECT_EQ(changes.added->activeVoxelCount(), 0u);
}

TEST(ChangeDetection, MissingMasksAreRefused) {
    const Street s;
    Observation broken = s.b;
    broken.masks.free.reset();
    EXPECT_THROW((void)DetectChanges(s.a, broken, kVoxel), InvalidArgumentError);
    EXPECT_THROW((void)DetectChanges(s.a, s.b, 0.0), InvalidArgumentError);
}

TEST(Region, ParsesBoxesAndPolygonsAndNamesBadText) {
    const core::Region box = core::Region::Parse("0,-10,50,10");
    EXPECT_TRUE(box.Contains(25.0, 0.0));
    EXPECT_FALSE(box.Contains(51.0, 0.0));
    EXPECT_TRUE(box.Covers({1.0, 1.0}, {2.0, 2.0}));
    const core::Region l_shape = core::Region::Parse("0,0,4,0,4,1,1,1,1,4,0,4");
    EXPECT_TRUE(l_shape.Contains(0.5, 3.0));
    EXPECT_FALSE(l_shape.Contains(3.0, 3.0));
    EXPECT_FALSE(l_shape.Covers({0.1, 0.1}, {0.2, 0.2}));  // conservative for polygons
    for (const char* bad : {"", "1,2,3", "0,0,a,1", "5,0,1,1", "0,0,1,0,2,0", "1,2,3,4,5"}) {
        try {
            (void)core::Region::Parse(bad);
            ADD_FAILURE() << "accepted '" << bad << "'";
        } catch (const InvalidArgumentError& e) {
            EXPECT_NE(std::string(e.what()).find("region"), std::string::npos) << e.what();
        }
    }
}

}  // namespace
}  // namespace strata::change
