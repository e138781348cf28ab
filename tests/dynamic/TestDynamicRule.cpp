// The rule of dynamic::FindDynamic on voxels set by hand (docs/dynamic.md, "The rule"): a voxel
// points ended in that the map says is free is removed when its neighbourhood was crossed, kept
// (restored) when a neighbour never was; occupied voxels are never touched.
#include <gtest/gtest.h>

#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/dynamic/Dynamic.hpp"

namespace strata::dynamic {
namespace {

constexpr double kVoxel = 0.5;

struct Scene {
    core::VoxelMap map = core::VoxelMap::Create(kVoxel);
    SeenSpace seen{openvdb::MaskGrid::create(), openvdb::MaskGrid::create()};

    // A voxel points ended in, with its log-odds now.
    void Hit(const openvdb::Coord& c, float log_odds) {
        seen.hit->tree().setValueOn(c);
        map.occupancy->tree().setValueOn(c, log_odds);
        if (log_odds <= 0.0F) seen.crossed->tree().setValueOn(c);  // free now: a ray crossed it
    }
    // Every voxel of the box [lo, hi] crossed by some ray.
    void Cross(const openvdb::Coord& lo, const openvdb::Coord& hi) {
        for (int x = lo.x(); x <= hi.x(); ++x) {
            for (int y = lo.y(); y <= hi.y(); ++y) {
                for (int z = lo.z(); z <= hi.z(); ++z) seen.crossed->tree().setValueOn({x, y, z});
            }
        }
    }
};

// The rule voxel by voxel: a lone voxel it removes stays removed (not kept as scattered).
DynamicConfig VoxelByVoxel() {
    DynamicConfig config;
    config.keep_scattered = false;
    return config;
}

bool Removed(const DynamicResult& r, const openvdb::Coord& c) {
    return r.removed->tree().isValueOn(c);
}
bool Restored(const DynamicResult& r, const openvdb::Coord& c) {
    return r.restored->tree().isValueOn(c);
}

TEST(DynamicRule, ErodedGroundIsRestoredAFloatingVoxelRemoved) {
    Scene s;
    s.Cross({-5, -5, 1}, {5, 5, 6});  // the air above the ground (z = 0) was seen through
    for (int x = -5; x <= 5; ++x) s.Hit({x, 0, 0}, -0.5F);  // ground the grazing rays eroded
    s.Hit({0, 0, 3}, -1.0F);                                // something that passed, in the air
    s.Hit({2, 2, 3}, 2.0F);                                 // occupied now: never touched
    const DynamicResult r = FindDynamic(s.map, s.seen, VoxelByVoxel());
    for (int x = -5; x <= 5; ++x) EXPECT_TRUE(Restored(r, {x, 0, 0})) << x;
    EXPECT_TRUE(Removed(r, {0, 0, 3}));
    EXPECT_FALSE(Removed(r, {2, 2, 3}) || Restored(r, {2, 2, 3}));
    EXPECT_EQ(r.candidates, 12u);
    EXPECT_EQ(r.removed_voxels(), 1u);
    EXPECT_EQ(r.occupied, 1u);
    EXPECT_EQ(r.static_voxels, 12u);
}

TEST(DynamicRule, TheMarginDecidesAtTheEdgeOfTheSeenSpace) {
    Scene s;
    s.Cross({0, 0, 0}, {4, 4, 4});
    s.Hit({1, 1, 1}, -1.0F);  // every face neighbour crossed, so is the cube
    s.Hit({0, 2, 2}, -1.0F);  // at the edge: its -x neighbour was never crossed
    DynamicConfig faces = VoxelByVoxel();
    faces.neighbourhood = Neighbourhood::kFaces;
    const DynamicResult r = FindDynamic(s.map, s.seen, faces);
    EXPECT_TRUE(Removed(r, {1, 1, 1}));
    EXPECT_TRUE(Restored(r, {0, 2, 2}));
    DynamicConfig none = faces;
    none.margin_voxels = 0;  // the voxel alone: both seen through
    EXPECT_TRUE(Removed(FindDynamic(s.map, s.seen, none), {0, 2, 2}));
    DynamicConfig wide = faces;
    wide.margin_voxels = 2;  // (1, 1, 1) is 1 voxel from the edge: kept
    EXPECT_TRUE(Restored(FindDynamic(s.map, s.seen, wide), {1, 1, 1}));
    // A diagonal neighbour never crossed: the faces remove, the cube keeps.
    s.seen.crossed->tree().setValueOff({2, 2, 2});
    s.map.occupancy->tree().setValueOn({2, 2, 2}, 1.0F);
    EXPECT_TRUE(Removed(FindDynamic(s.map, s.seen, faces), {1, 1, 1}));
    DynamicConfig cube = VoxelByVoxel();
    cube.neighbourhood = Neighbourhood::kCube;
    EXPECT_TRUE(Restored(FindDynamic(s.map, s.seen, cube), {1, 1, 1}));
}

TEST(DynamicRule, TouchingVoxelsAreOneObjectSmallOnesScattered) {
    Scene s;
    s.Cross({-20, -20, -20}, {20, 20, 20});
    for (int x = 0; x < 10; ++x) s.Hit({x, 0, 0}, -1.0F);         // a trail, 10 voxels
    for (int x = 0; x < 9; ++x) s.Hit({x, 5, 1 + x % 2}, -1.0F);  // diagonal steps touch
    s.Hit({-10, -10, -10}, -1.0F);                                // alone
    DynamicConfig config;
    config.object_gap_voxels = 1;  // touching
    config.min_object_voxels = 8;
    const DynamicResult r = FindDynamic(s.map, s.seen, config);
    ASSERT_EQ(r.objects.size(), 2u);
    EXPECT_EQ(r.objects[0].id, 1);
    EXPECT_EQ(r.objects[0].voxels, 10u);
    EXPECT_EQ(r.objects[1].voxels, 9u);
    EXPECT_EQ(r.scattered, 1u);
    EXPECT_TRUE(r.objects[0].box.min().isApprox(Eigen::Vector3d(0, 0, 0)));
    EXPECT_TRUE(r.objects[0].box.max().isApprox(Eigen::Vector3d(10 * kVoxel, kVoxel, kVoxel)));
    EXPECT_EQ(r.removed->tree().getValue({-10, -10, -10}), 0);
    EXPECT_EQ(r.removed->tree().getValue({3, 0, 0}), 1);
}

TEST(DynamicRule, KeptScatteredGroupsStayStaticAndAreCountedOnce) {
    Scene s;
    s.Cross({-20, -20, -20}, {20, 20, 20});
    for (int x = 0; x < 10; ++x) s.Hit({x, 0, 0}, -1.0F);  // a trail: removed
    s.Hit({-10, -10, -10}, -1.0F);                         // alone and free: restored
    s.Hit({10, 10, 10}, 1.5F);                             // alone and occupied: as it was
    DynamicConfig config;
    config.occupied_too = true;
    config.keep_scattered = true;
    const DynamicResult r = FindDynamic(s.map, s.seen, config);
    ASSERT_EQ(r.objects.size(), 1u);
    EXPECT_EQ(r.removed_voxels(), 10u);
    EXPECT_EQ(r.scattered, 2u);
    EXPECT_TRUE(Restored(r, {-10, -10, -10}));
    EXPECT_FALSE(Removed(r, {10, 10, 10}) || Restored(r, {10, 10, 10}));
    EXPECT_EQ(r.removed_occupied, 0u);
    EXPECT_EQ(r.static_voxels, 2u);  // the occupied voxel and the restored one
    config.keep_scattered = false;   // removed, the occupied one too
    const DynamicResult all = FindDynamic(s.map, s.seen, config);
    EXPECT_EQ(all.removed_voxels(), 12u);
    EXPECT_EQ(all.removed_occupied, 1u);
    EXPECT_EQ(all.static_voxels, 0u);
}

TEST(DynamicRule, TheStaticMapKeepsRestoredVoxelsAndMarksRemovedOnes) {
    Scene s;
    s.Cross({-5, -5, 1}, {5, 5, 6});
    s.Hit({0, 0, 0}, -0.5F);
    s.Hit({0, 0, 3}, -1.0F);
    s.map.endpoints->tree().setValueOn({0, 0, 3}, 7);
    const DynamicConfig config = VoxelByVoxel();
    const DynamicResult r = FindDynamic(s.map, s.seen, config);
    ApplyDynamic(r, config, s.map);
    EXPECT_FLOAT_EQ(s.map.occupancy->tree().getValue({0, 0, 0}), config.restored_log_odds);
    EXPECT_LE(s.map.occupancy->tree().getValue({0, 0, 3}), 0.0F);
    EXPECT_FALSE(s.map.endpoints->tree().isValueOn({0, 0, 3}));
    EXPECT_EQ(s.map.label->tree().getValue({0, 0, 3}),
              static_cast<int32_t>(core::SemanticClass::kDynamic));
}

TEST(DynamicRule, BadInputIsRefused) {
    Scene s;
    DynamicConfig bad;
    bad.margin_voxels = 9;
    EXPECT_THROW((void)FindDynamic(s.map, s.seen, bad), InvalidArgumentError);
    bad = {};
    bad.restored_log_odds = 0.0F;
    EXPECT_THROW((void)FindDynamic(s.map, s.seen, bad), InvalidArgumentError);
    SeenSpace half{s.seen.crossed, nullptr};
    EXPECT_THROW((void)FindDynamic(s.map, half, DynamicConfig{}), InvalidArgumentError);
}

}  // namespace
}  // namespace strata::dynamic
