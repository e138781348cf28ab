// Commands that read a map tile by tile answer what reading it whole answers (docs/scale.md).
#include <gtest/gtest.h>

#include <map>

#include "StoreTestUtil.hpp"
#include "strata/core/Labels.hpp"
#include "strata/pipeline/Info.hpp"

namespace strata::pipeline {
namespace {

namespace fs = std::filesystem;

TEST(TileByTile, InfoCountsEqualTheWholeMapsCounts) {
    store::MapStore map = store::test::NewMap(store::test::Temp("tiles_info"));
    (void)store::test::Write(map, store::test::Session(1, {0.4, 0.2, 0.0}, 3));
    (void)store::test::Write(map, store::test::Session(9, {3.1, -1.7, 0.3}, 2));
    const nlohmann::json j = DescribeMap(map, "");
    ASSERT_GT(j["tiles"].get<size_t>(), 20u);  // 3.2 m tiles: the rooms span many
    const core::VoxelMap whole = map.LoadMap(map.Latest());
    size_t occupied = 0, free = 0;
    std::map<std::string, size_t> classes;
    auto label = whole.label->getConstAccessor();
    for (auto it = whole.occupancy->cbeginValueOn(); it; ++it) {
        if (*it > 0.0f) {
            ++occupied;
            int32_t v = 0;
            ++classes[core::ClassName(label.probeValue(it.getCoord(), v)
                                          ? static_cast<core::SemanticClass>(v)
                                          : core::SemanticClass::kUnknown)];
        } else {
            ++free;
        }
    }
    EXPECT_EQ(j["occupied_voxels"].get<size_t>(), occupied);
    EXPECT_EQ(j["free_voxels"].get<size_t>(), free);
    using Counts = std::map<std::string, size_t>;
    EXPECT_EQ(j["classes"].get<Counts>(), classes);
    EXPECT_EQ(classes.size(), 2u);  // ground and building
    const openvdb::CoordBBox box = whole.occupancy->evalActiveVoxelBoundingBox();
    const double s = whole.voxel_size;
    EXPECT_NEAR(j["extent_min"][0].get<double>(), box.min().x() * s, 1e-3);
    EXPECT_NEAR(j["extent_max"][2].get<double>(), (box.max().z() + 1) * s, 1e-3);
    // As of the first session too.
    const nlohmann::json first = DescribeMap(map, "1");
    EXPECT_LT(first["occupied_voxels"].get<size_t>(), occupied);
    EXPECT_EQ(first["commit"].get<int64_t>(), map.AsOf(1).commit);
}

}  // namespace
}  // namespace strata::pipeline
