#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <sys/resource.h>

#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>

#include "ExportTestMap.hpp"
#include "strata/io/VdbExport.hpp"

namespace strata::io {
namespace {

using namespace export_test;
constexpr float kTolerance = 1e-6f;

openvdb::GridPtrVec ReadGrids(const fs::path& path, openvdb::MetaMap::Ptr* file_meta = nullptr) {
    openvdb::io::File file(path.string());
    file.open();
    openvdb::GridPtrVec grids = *file.getGrids();
    if (file_meta) *file_meta = file.getMetadata();
    file.close();
    return grids;
}

template <typename GridT>
typename GridT::Ptr Find(const openvdb::GridPtrVec& grids, const std::string& name) {
    for (const auto& g : grids) {
        if (g->getName() == name) return openvdb::gridPtrCast<GridT>(g);
    }
    return nullptr;
}

// Same active voxels (tiles compared voxel by voxel) with the same values.
template <typename GridT>
void ExpectSameGrid(const GridT& expected, const GridT& actual) {
    EXPECT_EQ(expected.activeVoxelCount(), actual.activeVoxelCount()) << expected.getName();
    auto acc = actual.getConstAccessor();
    for (auto it = expected.cbeginValueOn(); it; ++it) {
        openvdb::CoordBBox bbox;
        it.getBoundingBox(bbox);
        for (auto ijk = bbox.begin(); ijk; ++ijk) {
            ASSERT_TRUE(acc.isValueOn(*ijk)) << expected.getName() << " " << *ijk;
            ASSERT_EQ(acc.getValue(*ijk), *it) << expected.getName() << " " << *ijk;
        }
    }
    EXPECT_EQ(expected.transform(), actual.transform());
}

std::string RunCommand(const std::string& command) {
    std::string out;
    std::unique_ptr<FILE, int (*)(FILE*)> pipe(::popen(command.c_str(), "r"), ::pclose);
    if (!pipe) return out;
    char buf[4096];
    for (size_t n; (n = std::fread(buf, 1, sizeof buf, pipe.get())) > 0;) out.append(buf, n);
    return out;
}

TEST(VdbExport, RoundTripKeepsEveryGridAndAddsViewerGrids) {
    const ScratchDir dir("vdb_roundtrip");
    const core::VoxelMap map = MakeExportTestMap(Eigen::Vector3d(1000.5, -20.25, 3.0));
    WriteVdb(map, dir / "map.vdb");
    EXPECT_EQ(dir.EntryCount(), 1);  // no temporary left behind

    openvdb::MetaMap::Ptr file_meta;
    const openvdb::GridPtrVec grids = ReadGrids(dir / "map.vdb", &file_meta);
    ASSERT_EQ(grids.size(), 7u);
    const auto occupancy = Find<openvdb::FloatGrid>(grids, "occupancy");
    const auto label = Find<openvdb::Int32Grid>(grids, "label");
    const auto label_weight = Find<openvdb::FloatGrid>(grids, "label_weight");
    const auto hits = Find<openvdb::Int32Grid>(grids, "hits");
    const auto point_mean = Find<openvdb::Vec3SGrid>(grids, "point_mean");
    const auto density = Find<openvdb::FloatGrid>(grids, "density");
    const auto color = Find<openvdb::Vec3SGrid>(grids, "color");
    ASSERT_TRUE(occupancy && label && label_weight && hits && point_mean && density && color);
    ExpectSameGrid(*map.occupancy, *occupancy);
    ExpectSameGrid(*map.label, *label);
    ExpectSameGrid(*map.label_weight, *label_weight);
    // Endpoints come out expanded, as other tools read them: counts and offsets in metres.
    EXPECT_EQ(hits->activeVoxelCount(), map.endpoints->activeVoxelCount());
    EXPECT_EQ(point_mean->activeVoxelCount(), map.endpoints->activeVoxelCount());
    for (auto it = map.endpoints->cbeginValueOn(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        EXPECT_EQ(hits->tree().getValue(c), map.Hits(c)) << c;
        const openvdb::Vec3s m = point_mean->tree().getValue(c);
        const Eigen::Vector3d expected = map.PointMean(c) - map.VoxelCenter(c);
        EXPECT_NEAR((Eigen::Vector3d(m[0], m[1], m[2]) - expected).norm(), 0.0, 1e-6) << c;
    }

    // The map reads back as a map, georeference included.
    const core::VoxelMap back = core::VoxelMap::FromGrids(grids);
    EXPECT_DOUBLE_EQ(back.voxel_size, kVoxelSize);
    EXPECT_TRUE(back.origin.isApprox(map.origin));

    // Metadata explains the file under vdb_print -m.
    for (const auto& g : grids) {
        EXPECT_TRUE(g->getMetadata<openvdb::StringMetadata>("units")) << g->getName();
        EXPECT_EQ(g->metaValue<std::string>("producer").rfind("strata", 0), 0u) << g->getName();
        EXPECT_TRUE(g->getMetadata<openvdb::Vec3DMetadata>("origin")) << g->getName();
    }
    EXPECT_EQ(label->metaValue<std::string>("class_legend"), core::LegendJson());
    EXPECT_EQ(color->metaValue<std::string>("class_legend"), core::LegendJson());
    ASSERT_TRUE(file_meta);
    EXPECT_DOUBLE_EQ(file_meta->metaValue<double>("voxel_size"), kVoxelSize);
    EXPECT_EQ(file_meta->metaValue<openvdb::Vec3d>("origin"), openvdb::Vec3d(1000.5, -20.25, 3.0));
}

TEST(VdbExport, DensityAndColorCoverOccupiedVoxelsOnly) {
    const ScratchDir dir("vdb_viewer_grids");
    const core::VoxelMap map = MakeExportTestMap();
    WriteVdb(map, dir / "map.vdb");
    const openvdb::GridPtrVec grids = ReadGrids(dir / "map.vdb");
    const auto density = Find<openvdb::FloatGrid>(grids, "density");
    const auto color = Find<openvdb::Vec3SGrid>(grids, "color");
    ASSERT_TRUE(density && color);
    EXPECT_EQ(density->getGridClass(), openvdb::GRID_FOG_VOLUME);
    EXPECT_EQ(density->transform(), map.occupancy->transform());

    const auto expect_rgb = [](SemanticClass c) {
        const core::Rgb rgb = core::ClassColor(c);
        return openvdb::Vec3s(rgb.r, rgb.g, rgb.b) / 255.0f;
    };
    const openvdb::Coord car(3, 0, 2);
    EXPECT_NEAR(density->tree().getValue(car), core::Probability(kCarLogOdds), kTolerance);
    EXPECT_TRUE(color->tree().getValue(car).eq(expect_rgb(SemanticClass::kVehicle)));
    const openvdb::Coord floor(-9, -6, 0);
    EXPECT_NEAR(density->tree().getValue(floor), core::Probability(kFloorLogOdds), kTolerance);
    EXPECT_TRUE(color->tree().getValue(floor).eq(expect_rgb(SemanticClass::kGround)));
    // Inside an occupied tile every voxel gets a value.
    ASSERT_GE(map.occupancy->tree().activeTileCount(), 2u);
    const openvdb::Coord in_tile(27, 20, 3);
    EXPECT_NEAR(density->tree().getValue(in_tile), core::Probability(1.0f), kTolerance);
    EXPECT_TRUE(color->tree().getValue(in_tile).eq(expect_rgb(SemanticClass::kBuilding)));
    // Free, zero and unknown voxels stay inactive at 0.
    for (const openvdb::Coord& ijk :
         {openvdb::Coord(-9, -6, 2), kZeroVoxel, kHole, openvdb::Coord(20, 20, 3)}) {
        EXPECT_FALSE(density->tree().isValueOn(ijk)) << ijk;
        EXPECT_EQ(density->tree().getValue(ijk), 0.0f) << ijk;
        EXPECT_FALSE(color->tree().isValueOn(ijk)) << ijk;
    }
    // One density/color voxel per occupied voxel.
    openvdb::Index64 occupied = 0;
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it > 0.0f) occupied += it.getVoxelCount();
    }
    EXPECT_EQ(density->activeVoxelCount(), occupied);
    EXPECT_EQ(color->activeVoxelCount(), occupied);
}

TEST(VdbExport, OptionsLeaveOutViewerGrids) {
    const ScratchDir dir("vdb_options");
    VdbExportOptions options;
    options.include_density = false;
    options.include_color = false;
    WriteVdb(MakeExportTestMap(), dir / "map.vdb", options);
    const openvdb::GridPtrVec grids = ReadGrids(dir / "map.vdb");
    EXPECT_EQ(grids.size(), 5u);
    EXPECT_FALSE(Find<openvdb::FloatGrid>(grids, "density"));
}

TEST(VdbExport, VdbPrintListsEveryGrid) {
    if (!fs::exists("/usr/bin/vdb_print")) GTEST_SKIP() << "vdb_print is not installed";
    const ScratchDir dir("vdb_print");
    WriteVdb(MakeExportTestMap(), dir / "map.vdb");
    // vdb_print exits 0 even when it cannot read a file, so check what it printed.
    const std::string out =
        RunCommand("/usr/bin/vdb_print -l '" + (dir / "map.vdb").string() + "' 2>&1");
    for (const char* name :
         {"occupancy", "label", "label_weight", "hits", "point_mean", "density", "color"}) {
        EXPECT_NE(out.find(name), std::string::npos) << name << " missing in:\n" << out;
    }
    EXPECT_NE(out.find("vec3s"), std::string::npos) << out;
}

TEST(VdbExport, MissingDirectoryThrowsNamingThePath) {
    const ScratchDir dir("vdb_missing");
    const fs::path path = dir / "no/such/dir/map.vdb";
    ExpectErrorNaming(path, [&] { WriteVdb(MakeExportTestMap(), path); });
    EXPECT_EQ(dir.EntryCount(), 0);
}

// A full disk, simulated with a file-size limit: the write fails, the previous file survives and
// no temporary file is left behind.
TEST(VdbExport, FullDiskThrowsAndKeepsThePreviousFile) {
    const ScratchDir dir("vdb_full");
    const fs::path path = dir / "map.vdb";
    std::ofstream(path) << "previous export";
    rlimit old_limit{};
    ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old_limit), 0);
    const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);  // get EFBIG instead of a signal
    rlimit small = old_limit;
    small.rlim_cur = 1024;  // far below the size of the export
    ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
    bool threw = false;
    try {
        WriteVdb(MakeExportTestMap(), path);
    } catch (const std::runtime_error& e) {
        threw = std::string(e.what()).find(path.string()) != std::string::npos;
    }
    ::setrlimit(RLIMIT_FSIZE, &old_limit);
    std::signal(SIGXFSZ, old_handler);
    EXPECT_TRUE(threw);
    std::ifstream in(path);
    std::string content;
    std::getline(in, content);
    EXPECT_EQ(content, "previous export");
    EXPECT_EQ(dir.EntryCount(), 1);
}

}  // namespace
}  // namespace strata::io
