// io::WritePcd: the occupied voxels' centres as a binary PCD, read back by an independent reader
// (@loaders.gl/pcd, tests/io/read_pcd.mjs) and by strata's own (classes, float64 coordinates).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ExportTestMap.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/PcdExport.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::io {
namespace {

using namespace export_test;

// A float32 coordinate of a centre within 50 m of the origin: exact to 4e-6 m.
constexpr double kFloatTolerance = 1e-5;

std::vector<std::array<double, 4>> ExpectedCentres(const core::VoxelMap& map) {
    std::vector<std::array<double, 4>> out;
    const auto labels = map.label->getConstAccessor();
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (!(*it > 0.0F)) continue;
        openvdb::CoordBBox box;
        it.getBoundingBox(box);
        for (auto ijk = box.begin(); ijk; ++ijk) {
            const Eigen::Vector3d p = map.VoxelCenter(*ijk) + map.origin;
            out.push_back({p.x(), p.y(), p.z(), static_cast<double>(labels.getValue(*ijk))});
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

void Write(const core::VoxelMap& map, const fs::path& path) {
    WritePcd(
        map, [&](const std::function<void(const core::VoxelMap&)>& visit) { visit(map); }, path);
}

// What read_pcd.mjs prints for `file`; fails the test when node or the package is missing.
nlohmann::json ReadWithLoadersGl(const fs::path& file) {
    const fs::path root(STRATA_SOURCE_DIR);
    const std::string command = "NODE_PATH=" + (root / "build-deps/npm/node_modules").string() +
                                " node " + (root / "tests/io/read_pcd.mjs").string() + " " +
                                file.string();
    FILE* pipe = ::popen(command.c_str(), "r");
    std::string out;
    char buffer[65536];
    for (size_t n; pipe && (n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0;) {
        out.append(buffer, n);
    }
    const int status = pipe ? ::pclose(pipe) : -1;
    if (status != 0) {
        ADD_FAILURE() << command << " failed (" << status
                      << "): node and @loaders.gl/pcd come from tools/setup.sh";
        return {};
    }
    return nlohmann::json::parse(out);
}

TEST(PcdExport, LoadersGlReadsEveryOccupiedVoxelCentre) {
    const core::VoxelMap map = MakeExportTestMap();
    const ScratchDir dir("pcd_loadersgl");
    const fs::path path = dir / "centres.pcd";
    Write(map, path);
    const nlohmann::json cloud = ReadWithLoadersGl(path);
    ASSERT_FALSE(cloud.is_null());
    const std::vector<std::array<double, 4>> expected = ExpectedCentres(map);
    EXPECT_EQ(cloud["fields"], nlohmann::json({"x", "y", "z", "intensity"}));
    EXPECT_EQ(cloud["data"], "binary");
    ASSERT_EQ(cloud["points"].get<size_t>(), expected.size());
    const auto& flat = cloud["positions"];
    ASSERT_EQ(flat.size(), 3 * expected.size());
    std::vector<std::array<double, 3>> read;
    for (size_t i = 0; i < expected.size(); ++i) {
        read.push_back({flat[3 * i].get<double>(), flat[3 * i + 1].get<double>(),
                        flat[3 * i + 2].get<double>()});
    }
    std::sort(read.begin(), read.end());
    for (size_t i = 0; i < read.size(); ++i) {
        for (int a = 0; a < 3; ++a) {
            ASSERT_NEAR(read[i][a], expected[i][a], kFloatTolerance) << i;
        }
    }
}

TEST(PcdExport, StrataReadsClassesAndAnOriginsDoublesBack) {
    const std::vector<Eigen::Vector3d> origins = {Eigen::Vector3d::Zero(),
                                                  Eigen::Vector3d(512345.25, 5401234.5, 212.0)};
    for (const Eigen::Vector3d& origin : origins) {
        const core::VoxelMap map = MakeExportTestMap(origin);
        const ScratchDir dir("pcd_classes");
        const fs::path path = dir / "classes.pcd";
        Write(map, path);
        const core::Scan scan = ReadPcd(path);  // no origin subtracted: world coordinates
        const std::vector<std::array<double, 4>> expected = ExpectedCentres(map);
        ASSERT_EQ(scan.points.size(), expected.size());
        ASSERT_EQ(scan.intensity.size(), expected.size());
        std::vector<std::array<double, 4>> read;
        for (size_t i = 0; i < scan.points.size(); ++i) {
            const Eigen::Vector3d& p = scan.points[i];
            read.push_back({p.x(), p.y(), p.z(), static_cast<double>(scan.intensity[i])});
        }
        std::sort(read.begin(), read.end());
        // Doubles with an origin: exact; floats without: to float precision.
        const double tolerance = origin.isZero() ? kFloatTolerance : 0.0;
        for (size_t i = 0; i < read.size(); ++i) {
            for (int a = 0; a < 4; ++a) ASSERT_NEAR(read[i][a], expected[i][a], tolerance) << i;
        }
    }
}

TEST(PcdExport, BadInputFailsNamingTheFileAndLeavesNone) {
    const ScratchDir dir("pcd_bad");
    PcdPoints cloud;
    cloud.points = {Eigen::Vector3d(1, 2, 3)};
    ExpectErrorNaming(dir / "mismatch.pcd", [&] { WritePcd(cloud, "", dir / "mismatch.pcd"); });
    cloud.intensity = {7.0F};
    const fs::path nowhere = dir / "no_such_dir" / "out.pcd";
    ExpectErrorNaming(nowhere, [&] { WritePcd(cloud, "", nowhere); });
    EXPECT_EQ(dir.EntryCount(), 0);
}

}  // namespace
}  // namespace strata::io
