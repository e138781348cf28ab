// Open-or-create: a new map gets the request's settings (its origin from a LAS header when
// georeferenced), an existing one is opened with its own rule, and a request that contradicts
// it is refused before anything is written.
#include <gtest/gtest.h>

#include "../io/ReaderTestFiles.hpp"
#include "PipelineTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/PointCloudReaders.hpp"
#include "strata/pipeline/OpenOrCreate.hpp"

namespace strata::pipeline::test {
namespace {

constexpr double kExactM = 1e-12;

TEST(PipelineOpenOrCreate, CreatesANewMapWithTheRequestAndOpensItAfterwards) {
    const fs::path dir = Temp("create");
    MapRequest request;
    request.voxel_size_m = 0.25;
    request.tile_size_m = 32.0;
    request.origin = Eigen::Vector3d(500000.0, 4100000.0, 12.0);
    request.rule.max_range_m = 40.0;
    {
        const OpenedMap created = OpenOrCreateMap(dir, request);
        EXPECT_TRUE(created.created);
        EXPECT_TRUE(created.map.writable());
        EXPECT_NEAR(created.map.settings().voxel_size_m, 0.25, kExactM);
        EXPECT_NEAR(created.map.settings().tile_size_m(), 32.0, kExactM);
        EXPECT_TRUE(created.map.settings().origin.isApprox(*request.origin));
        EXPECT_EQ(created.rule.max_range_m, 40.0);
    }
    // Opened again without flags: the map's own settings and rule.
    const OpenedMap opened = OpenOrCreateMap(dir, MapRequest{});
    EXPECT_FALSE(opened.created);
    EXPECT_NEAR(opened.map.settings().voxel_size_m, 0.25, kExactM);
    EXPECT_EQ(opened.rule.max_range_m, 40.0);
}

TEST(PipelineOpenOrCreate, ARequestThatContradictsTheMapIsRefusedAndChangesNothing) {
    const fs::path dir = Temp("contradict");
    (void)IntegrateRoom(dir, "contradict");
    const MapState before = StateOf(dir);
    MapRequest voxel;
    voxel.voxel_size_m = 0.5;
    try {
        (void)OpenOrCreateMap(dir, voxel);
        ADD_FAILURE() << "a second voxel size was accepted";
    } catch (const InvalidArgumentError& e) {
        EXPECT_NE(std::string(e.what()).find("has voxel size 0.100000 m; --voxel 0.500000"),
                  std::string::npos)
            << e.what();
    }
    MapRequest range;
    range.rule.max_range_m = 10.0;
    EXPECT_THROW((void)OpenOrCreateMap(dir, range), InvalidArgumentError);
    EXPECT_EQ(StateOf(dir), before);
}

TEST(PipelineOpenOrCreate, AGeoreferencedLasFileGivesANewMapItsOrigin) {
    const fs::path las = Temp("georeference.las");
    {
        std::ofstream out(las, std::ios::binary);
        out << io::test_files::MakeLas(2, 1, 28);
    }
    const Eigen::Vector3d min = io::ReadLasHeader(las).min;
    MapRequest request;
    request.georeference_from = las;
    const store::StoreSettings settings = NewMapSettings(request);
    EXPECT_TRUE(settings.origin.isApprox(min.array().floor().matrix())) << settings.origin;
    EXPECT_GT(settings.origin.norm(), 0.0);
    // An origin given wins; a file of another format georeferences nothing.
    request.origin = Eigen::Vector3d(1.0, 2.0, 3.0);
    EXPECT_TRUE(NewMapSettings(request).origin.isApprox(*request.origin));
    MapRequest pcd;
    pcd.georeference_from = "scan.pcd";
    EXPECT_TRUE(NewMapSettings(pcd).origin.isZero());
}

}  // namespace
}  // namespace strata::pipeline::test
