// End-to-end tests of the `strata` program: it runs, explains failures, and never damages a map.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "CliTestUtil.hpp"
#include "RealData.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PoseFiles.hpp"
#include "strata/store/MapStore.hpp"

namespace {

namespace fs = std::filesystem;

using strata::store::MapStore;
using strata::tools::test::FailedWith;
using strata::tools::test::kBadFormat;
using strata::tools::test::kNotFound;
using strata::tools::test::kRefused;
using strata::tools::test::kUsage;
using strata::tools::test::MakeSequence;
using strata::tools::test::MapFiles;
using strata::tools::test::Result;
using strata::tools::test::Strata;
using strata::tools::test::Temp;

MapStore OpenForReading(const fs::path& map) {
    return MapStore::Open(map, MapStore::Access::kRead);
}

TEST(Cli, IntegrateInfoAndExportEndToEnd) {
    const fs::path seq = MakeSequence(Temp("seq"));
    const fs::path map = Temp("map");
    const Result integrate = Strata("integrate " + map.string() + " --kitti " + seq.string() +
                                    " --voxel 0.1 --max-range 20 --profile");
    ASSERT_EQ(integrate.code, 0) << integrate.out;
    // --profile: where the session's time went, each part once (none counted twice: what is
    // left, "other", is not negative) and the kernel's parts measured.
    double read = -1, prepare = -1, mark = -1, apply = -1, write = -1, catalog = -1, other = -1;
    const size_t at = integrate.out.find("time: reading");
    ASSERT_NE(at, std::string::npos) << integrate.out;
    ASSERT_EQ(std::sscanf(integrate.out.c_str() + at,
                          "time: reading %lf s, preparing %lf s, marking %lf s, applying %lf s, "
                          "writing tiles %lf s, catalog %lf s, other %lf s",
                          &read, &prepare, &mark, &apply, &write, &catalog, &other),
              7)
        << integrate.out;
    for (const double part : {read, prepare, mark, apply, write, catalog}) EXPECT_GE(part, 0.0);
    EXPECT_GT(prepare, 0.0);
    EXPECT_GT(mark, 0.0);
    EXPECT_GT(write, 0.0);
    EXPECT_GE(other, -1e-9) << integrate.out;

    const Result info = Strata("info " + map.string() + " --json");
    ASSERT_EQ(info.code, 0) << info.out;
    const auto j = nlohmann::json::parse(info.out.substr(info.out.find('{')));
    EXPECT_DOUBLE_EQ(j["voxel_size_m"].get<double>(), 0.1);
    EXPECT_GT(j["occupied_voxels"].get<size_t>(), 1000u);
    EXPECT_GT(j["free_voxels"].get<size_t>(), j["occupied_voxels"].get<size_t>());
    ASSERT_EQ(j["sessions"].size(), 1u);
    EXPECT_EQ(j["sessions"][0]["scans"], 3);

    for (const std::string ext : {"vdb", "bt", "ot", "ply", "png"}) {
        const fs::path out = Temp("export." + ext);
        const Result r = Strata("export " + map.string() + " --out " + out.string());
        EXPECT_EQ(r.code, 0) << r.out;
        EXPECT_GT(fs::file_size(out), 100u) << ext;
    }
}

TEST(Cli, BadArgumentsAndInputsFailWithAMessage) {
    EXPECT_TRUE(FailedWith(Strata(""), kUsage, "A subcommand is required"));
    EXPECT_TRUE(FailedWith(Strata("info /nonexistent/map"), kNotFound, "/nonexistent/map"));
    const Result both = Strata("integrate " + Temp("m").string() + " --kitti a --scans b.pcd");
    EXPECT_TRUE(FailedWith(both, kUsage, "exactly one of"));
    // An export format nobody knows, asked of a map that exists: refused naming the file, and
    // nothing written.
    const fs::path map = Temp("bad_export");
    ASSERT_EQ(Strata("integrate " + map.string() + " --kitti " +
                     MakeSequence(Temp("bad_export_seq")).string())
                  .code,
              0);
    const fs::path out = Temp("export.xyz");
    EXPECT_TRUE(FailedWith(Strata("export " + map.string() + " --out " + out.string()), kUsage,
                           "unknown export format 'xyz'"));
    EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, FailedIntegrationLeavesTheMapUntouched) {
    const fs::path seq = MakeSequence(Temp("seq2"));
    const fs::path map = Temp("map2");
    ASSERT_EQ(Strata("integrate " + map.string() + " --kitti " + seq.string()).code, 0);
    const auto before = MapFiles(map);
    // A scan truncated mid-record: the second session must fail and change nothing.
    fs::resize_file(seq / "velodyne" / "000002.bin", 16 * 100 + 7);
    const Result r = Strata("integrate " + map.string() + " --kitti " + seq.string());
    EXPECT_TRUE(FailedWith(r, kBadFormat, "000002.bin"));
    EXPECT_EQ(MapFiles(map), before);
    EXPECT_EQ(OpenForReading(map).Latest().sessions.size(), 1u);
    // A different voxel size for an existing map is refused.
    EXPECT_TRUE(FailedWith(Strata("integrate " + map.string() + " --kitti " + seq.string() +
                                  " --voxel 0.5 --frames 0:2"),
                           kUsage, "voxel"));
    EXPECT_EQ(MapFiles(map), before);
}

TEST(Cli, AScanTooFineForMemoryIsRefusedNamingIt) {
    // A 100 m hall at 1 cm voxels: every ray crosses thousands of fresh leaves, far over the
    // per-scan budget (IntegrationConfig::max_update_bytes); refused before the memory goes, and
    // no map is left behind.
    strata::tools::test::SequenceSpec spec;
    spec.scans = 1;
    spec.room_half_m = Eigen::Vector3d(50.0, 40.0, 5.0);
    const fs::path seq = MakeSequence(Temp("seq_fine"), spec);
    const fs::path map = Temp("map_fine");
    const Result r =
        Strata("integrate " + map.string() + " --kitti " + seq.string() + " --voxel 0.01");
    EXPECT_TRUE(FailedWith(r, kRefused, "000000.bin"));
    EXPECT_NE(r.out.find("larger voxel size"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(map / "catalog.sqlite")) << "no map is left behind";
}

TEST(Cli, IntegratesTextScansWithAPoseFile) {
    const fs::path dir = Temp("text");
    fs::create_directories(dir);
    std::vector<Eigen::Isometry3d> poses;
    for (int k = 0; k < 2; ++k) {
        std::ofstream out(dir / ("scan" + std::to_string(k) + ".txt"));
        out << "# a wall 4 m ahead\n";
        for (int i = -20; i <= 20; ++i) {
            for (int j = -10; j <= 10; ++j) out << 4.0 << " " << 0.1 * i << " " << 0.1 * j << "\n";
        }
        Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
        T.translation() = Eigen::Vector3d(0.0, 0.5 * k, 0.0);
        poses.push_back(T);
    }
    strata::io::WriteKittiPoses(dir / "poses.txt", poses);
    const fs::path map = Temp("textmap");
    const Result r = Strata("integrate " + map.string() + " --scans " +
                            (dir / "scan0.txt").string() + " " + (dir / "scan1.txt").string() +
                            " --poses " + (dir / "poses.txt").string() + " --voxel 0.1");
    ASSERT_EQ(r.code, 0) << r.out;
    const MapStore store = OpenForReading(map);
    ASSERT_EQ(store.Latest().sessions.at(0).scans, 2u);
    EXPECT_EQ(store.Scans(1).at(1).source, (dir / "scan1.txt").string());
    // The second scan is 0.5 m to the side: the wall reaches y = 2.5 m, observed as occupied.
    const auto loaded = store.LoadMap(store.Latest());
    const auto ijk = loaded.WorldToVoxel({4.05, 2.45, 0.05});
    EXPECT_GT(loaded.occupancy->tree().getValue(ijk), 0.0f);
}

TEST(Cli, IntegratesAGeoreferencedLasTileAsPointsOnly) {
    const fs::path las = fs::path(STRATA_DATA_DIR) / "autzen_las" / "autzen_trim.las";
    STRATA_SKIP_WITHOUT_DATA(las);
    const fs::path map = Temp("las");
    const Result r = Strata("integrate " + map.string() + " --scans " + las.string() +
                            " --points-only --voxel 2");
    ASSERT_EQ(r.code, 0) << r.out;
    const Result info = Strata("info " + map.string() + " --json");
    const auto j = nlohmann::json::parse(info.out.substr(info.out.find('{')));
    // State-plane feet: the origin keeps the big numbers, the grid holds small ones.
    EXPECT_GT(j["origin"][0].get<double>(), 1e5);
    EXPECT_EQ(j["free_voxels"].get<size_t>(), 0u);
    EXPECT_GT(j["occupied_voxels"].get<size_t>(), 1000u);
    EXPECT_GE(j["classes"]["ground"].get<size_t>(), 1u);
}

TEST(Cli, SimulatedSequenceIntegratesEndToEnd) {
    const fs::path scene = fs::path(STRATA_SOURCE_DIR) / "datasets" / "scenes" / "street.json";
    const fs::path seq = Temp("simseq");
    const Result sim = Strata("simulate --scene " + scene.string() + " --out " + seq.string() +
                              " --sensor vlp16 --max-scans 2 --seed 3");
    ASSERT_EQ(sim.code, 0) << sim.out;
    std::ifstream truth_file(seq / "ground_truth.json");
    const auto truth = nlohmann::json::parse(truth_file);
    for (const char* key : {"walls", "vehicles", "floors", "edits", "static_surface"}) {
        EXPECT_TRUE(truth.contains(key)) << key;
    }
    EXPECT_GE(truth["walls"].size(), 5u);
    const fs::path map = Temp("simmap");
    const Result integrate = Strata("integrate " + map.string() + " --kitti " + seq.string());
    ASSERT_EQ(integrate.code, 0) << integrate.out;
    const MapStore store = OpenForReading(map);
    EXPECT_GT(store.LoadMap(store.Latest()).label->activeVoxelCount(), 1000u);  // labelled
    const Result bad = Strata("simulate --scene /nonexistent/scene.json --out " + seq.string());
    EXPECT_TRUE(FailedWith(bad, kUsage, "/nonexistent/scene.json"));  // CLI11's own check
}

TEST(Cli, IntegratesRawBinScansAndRefusesAmbiguousOnesWithoutChangingTheMap) {
    const fs::path dir = Temp("bin");
    fs::create_directories(dir);
    std::vector<Eigen::Vector3d> wall;  // 41 x 21 = 861 points: 13776 bytes, only 16 divides
    for (int i = -20; i <= 20; ++i) {
        for (int j = -10; j <= 10; ++j) wall.emplace_back(4.0, 0.1 * i, 0.1 * j);
    }
    strata::io::WriteKittiBin(dir / "000000.bin", wall, {});
    const fs::path map = Temp("binmap");
    const Result r = Strata("integrate " + map.string() + " --scans " +
                            (dir / "000000.bin").string() + " --voxel 0.1");
    ASSERT_EQ(r.code, 0) << r.out;
    {
        const MapStore store = OpenForReading(map);
        const auto loaded = store.LoadMap(store.Latest());
        EXPECT_GT(loaded.occupancy->tree().getValue(loaded.WorldToVoxel({4.05, 0.05, 0.05})), 0.f);
    }
    const auto before = MapFiles(map);
    // 5 points = 80 bytes: 5 KITTI points or 4 nuScenes points. Refused, naming the file.
    strata::io::WriteKittiBin(dir / "000001.bin", {wall.begin(), wall.begin() + 5}, {});
    const Result ambiguous =
        Strata("integrate " + map.string() + " --scans " + (dir / "000001.bin").string());
    EXPECT_TRUE(FailedWith(ambiguous, kBadFormat, "000001.bin"));
    EXPECT_NE(ambiguous.out.find("--bin-fields"), std::string::npos) << ambiguous.out;
    EXPECT_EQ(MapFiles(map), before);
    EXPECT_TRUE(FailedWith(Strata("integrate " + map.string() + " --scans " +
                                  (dir / "000001.bin").string() + " --bin-fields 3"),
                           kUsage, "--bin-fields"));
    EXPECT_EQ(MapFiles(map), before);
    const Result given = Strata("integrate " + map.string() + " --scans " +
                                (dir / "000001.bin").string() + " --bin-fields 4");
    EXPECT_EQ(given.code, 0) << given.out;
    EXPECT_EQ(OpenForReading(map).Latest().sessions.size(), 2u);
}

}  // namespace
