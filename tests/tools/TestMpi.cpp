// `mpirun -n N strata integrate ...` and `strata walls` end to end (docs/scale.md): the map and
// the walls one process makes, and a rank killed mid-run leaves the map at its last commit.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>
#include <vector>

#include "CliTestUtil.hpp"
#include "DriveFolder.hpp"
#include "MapDiff.hpp"
#include "Sanitizer.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::tools::test {
namespace {

const char* const kMpirun = "mpirun --allow-run-as-root --oversubscribe";

Result Mpirun(int ranks, const std::string& args) {
    return Shell(std::string(kMpirun) + " -n " + std::to_string(ranks) + " " + STRATA_BINARY + " " +
                 args);
}

// The rank counts each command is compared on: two and three ranks, or only three under a
// sanitizer (STRATA_SANITIZER, tools/sanitize.sh), where every rank is an instrumented process
// and the two-rank run repeats the paths the three-rank run takes (hand-over, joining, rank 0's
// commit) at a minute of CI time per test (docs/reliability.md, "Sanitizers").
std::vector<int> RankCounts() {
    if (strata::testing::UnderSanitizer()) return {3};
    return {2, 3};
}

size_t Count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

// The map in `dir`, read whole, and every layer of its newest snapshot.
void ExpectSameStores(const fs::path& a_dir, const fs::path& b_dir) {
    const store::MapStore a = store::MapStore::Open(a_dir, store::MapStore::Access::kRead);
    const store::MapStore b = store::MapStore::Open(b_dir, store::MapStore::Access::kRead);
    EXPECT_EQ(testing::MapDifference(a.LoadMap(a.Latest()), b.LoadMap(b.Latest())), "");
    const store::Snapshot sa = a.Latest(), sb = b.Latest();
    ASSERT_EQ(sa.layers.size(), sb.layers.size());
    for (size_t i = 0; i < sa.layers.size(); ++i) {
        EXPECT_EQ(testing::LayerDifference(a.ReadLayer(sa.layers[i]), b.ReadLayer(sb.layers[i])),
                  "");
    }
}

TEST(MpiCli, IntegrateOnTwoAndThreeRanksGivesTheOneProcessMap) {
    SequenceSpec spec;
    spec.scans = 5;
    spec.room_half_m = Eigen::Vector3d(6.0, 4.0, 1.5);
    const fs::path seq = MakeSequence(Temp("mpi_seq"), spec);
    const std::string flags = " --kitti " + seq.string() + " --voxel 0.1 --tile-size 3.2";
    const fs::path one = Temp("mpi_one");
    ASSERT_EQ(Strata("integrate " + one.string() + flags).code, 0);
    for (int ranks : RankCounts()) {
        const fs::path many = Temp("mpi_many_" + std::to_string(ranks));
        const Result r = Mpirun(ranks, "integrate " + many.string() + flags);
        ASSERT_EQ(r.code, 0) << r.out;
        EXPECT_EQ(Count(r.out, "session 1 ("), 1u) << r.out;  // rank 0 reports, once
        ExpectSameStores(many, one);
        const Result check = Strata("check " + many.string());
        EXPECT_EQ(check.code, 0) << check.out;
    }
    // Commands that do not share their work run on rank 0 alone: one answer.
    const Result info = Mpirun(2, "info " + one.string());
    EXPECT_EQ(info.code, 0) << info.out;
    EXPECT_EQ(Count(info.out, "\nsessions:\n"), 1u) << info.out;
}

// --odometry under mpirun: rank 0 estimates the poses (and writes --poses-out) before anything
// reaches the map, every rank integrates its share at them: the map and the poses of one process.
TEST(MpiCli, IntegrateOdometryOnRanksGivesTheOneProcessMapAndPoses) {
    const fs::path seq = WriteDriveFolder("mpi_odometry_seq", 12);
    const std::string flags = " --kitti " + seq.string() + " --voxel 0.2 --odometry --poses-out ";
    const fs::path one = Temp("mpi_odometry_one"), one_poses = Temp("mpi_odometry_one.txt");
    const Result single = Strata("integrate " + one.string() + flags + one_poses.string());
    ASSERT_EQ(single.code, 0) << single.out;
    for (int ranks : RankCounts()) {
        const fs::path many = Temp("mpi_odometry_many_" + std::to_string(ranks));
        const fs::path poses = Temp("mpi_odometry_many_" + std::to_string(ranks) + ".txt");
        const Result r = Mpirun(ranks, "integrate " + many.string() + flags + poses.string());
        ASSERT_EQ(r.code, 0) << r.out;
        EXPECT_EQ(Count(r.out, "odometry: 12 scans posed"), 1u) << r.out;  // rank 0 reports
        EXPECT_EQ(ReadText(poses), ReadText(one_poses)) << ranks << " ranks";
        ExpectSameStores(many, one);
    }
    // A scan the odometry cannot register stops every rank, and nothing is left behind.
    const fs::path bad = WriteDriveFolder("mpi_odometry_elsewhere", 5, 3);
    const fs::path refused = Temp("mpi_odometry_refused");
    const Result r = Mpirun(RankCounts().back(), "integrate " + refused.string() + " --kitti " +
                                                     bad.string() + " --voxel 0.2 --odometry");
    EXPECT_NE(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("scan 3 ("), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(refused));
}

TEST(MpiCli, WallsOnTwoAndThreeRanksAreTheOneProcessWalls) {
    SequenceSpec spec;
    spec.scans = 5;
    spec.room_half_m = Eigen::Vector3d(6.0, 4.0, 3.0);  // walls 6 m high
    const fs::path seq = MakeSequence(Temp("mpi_walls_seq"), spec);
    const fs::path map = Temp("mpi_walls_map");
    // Tiles of 3.2 m: every wall of the room crosses tile borders.
    ASSERT_EQ(Strata("integrate " + map.string() + " --kitti " + seq.string() +
                     " --voxel 0.1 --tile-size 3.2")
                  .code,
              0);
    const fs::path out = Temp("mpi_walls_out");
    fs::create_directories(out);
    const Result one = Strata("walls " + map.string() + " --no-save --memory-budget 0 --csv " +
                              (out / "one.csv").string());
    ASSERT_EQ(one.code, 0) << one.out;
    const std::string csv = ReadText(out / "one.csv");
    EXPECT_GE(std::count(csv.begin(), csv.end(), '\n'), 3) << csv;  // the header, 2+ walls
    for (int ranks : RankCounts()) {
        const fs::path csv_n = out / ("ranks" + std::to_string(ranks) + ".csv");
        // Three ranks also store the walls: rank 0 alone commits them.
        const std::string save = ranks == 2 ? " --no-save" : "";
        const Result r = Mpirun(
            ranks, "walls " + map.string() + save + " --memory-budget 0 --csv " + csv_n.string());
        ASSERT_EQ(r.code, 0) << r.out;
        EXPECT_EQ(Count(r.out, " walls from "), 1u) << r.out;  // rank 0 reports, once
        EXPECT_NE(r.out.find("over " + std::to_string(ranks) + " ranks"), std::string::npos)
            << r.out;
        EXPECT_EQ(ReadText(csv_n), csv) << ranks << " ranks";
    }
    // Levelled to the ground: the ranks sample it together and judge against the same plane.
    const std::string level = "walls " + map.string() + " --no-save --level-to-ground";
    const Result level_one =
        Strata(level + " --memory-budget 0 --csv " + (out / "level_one.csv").string());
    ASSERT_EQ(level_one.code, 0) << level_one.out;
    const Result level_two = Mpirun(2, level + " --csv " + (out / "level_two.csv").string());
    ASSERT_EQ(level_two.code, 0) << level_two.out;
    EXPECT_EQ(ReadText(out / "level_two.csv"), ReadText(out / "level_one.csv"));
    const Result check = Strata("check " + map.string());
    EXPECT_EQ(check.code, 0) << check.out;
    const Result again =
        Strata("walls " + map.string() + " --no-save --csv " + (out / "after.csv").string());
    EXPECT_EQ(again.code, 0) << again.out;
    EXPECT_EQ(ReadText(out / "after.csv"), csv);
    // Pictures of the whole map are refused on several ranks; the map stays as it was.
    const auto before = MapFiles(map);
    const Result png = Mpirun(2, "walls " + map.string() + " --png " + (out / "w.png").string());
    EXPECT_NE(png.code, 0) << png.out;
    EXPECT_NE(png.out.find("run them in one process"), std::string::npos) << png.out;
    EXPECT_FALSE(fs::exists(out / "w.png"));
    EXPECT_EQ(MapFiles(map), before);
}

// The vehicles report without what depends on how the map was read (time; Embree faces are
// summed over the blocks' scenes).
// The JSON report in a command's output (its other lines, and mpirun's, around it).
nlohmann::json ReportIn(const std::string& out) {
    const size_t first = out.find('{'), last = out.rfind('}');
    if (first == std::string::npos || last == std::string::npos || last < first) return {};
    return nlohmann::json::parse(out.substr(first, last - first + 1));
}

nlohmann::json VehiclesReport(const std::string& out) {
    nlohmann::json j = ReportIn(out);
    if (j.is_null()) return j;
    j.erase("seconds");
    j.erase("occluder_faces");
    return j;
}

TEST(MpiCli, VehiclesOnTwoAndThreeRanksAreTheOneProcessVehicles) {
    const fs::path seq = Temp("mpi_vehicles_seq"), map = Temp("mpi_vehicles_map");
    const std::string scene = std::string(STRATA_SOURCE_DIR) + "/datasets/scenes/parking.json";
    ASSERT_EQ(Strata("simulate --scene " + scene + " --out " + seq.string() +
                     " --max-scans 6 --no-picture")
                  .code,
              0);
    // Tiles of 3.2 m: the parked cars cross tile borders; a short ray range keeps the blocks'
    // windows smaller than the garage. Under a sanitizer 4.8 m, still many tiles for the ranks
    // to share: every tile read costs it far more than a release build (docs/reliability.md,
    // "Sanitizers").
    const std::string tile = strata::testing::UnderSanitizer() ? "4.8" : "3.2";
    ASSERT_EQ(Strata("integrate " + map.string() + " --kitti " + seq.string() +
                     " --voxel 0.1 --tile-size " + tile)
                  .code,
              0);
    const std::string args = " --json --ray-range 4 --memory-budget 0";
    const Result one = Strata("vehicles " + map.string() + " --no-save" + args);
    ASSERT_EQ(one.code, 0) << one.out;
    const nlohmann::json whole = VehiclesReport(one.out);
    ASSERT_GE(whole["vehicles"].size(), 3u) << one.out;
    for (int ranks : RankCounts()) {
        // Three ranks also store the cleaned map: rank 0 alone commits it.
        const std::string save = ranks == 2 ? " --no-save" : "";
        const Result r = Mpirun(ranks, "vehicles " + map.string() + save + args);
        ASSERT_EQ(r.code, 0) << r.out;
        EXPECT_EQ(VehiclesReport(r.out), whole) << ranks << " ranks";
    }
    const Result check = Strata("check " + map.string());
    EXPECT_EQ(check.code, 0) << check.out;
}

// `strata dynamic` on ranks: each judges its share of the tiles (3.2 m: the cars' trails cross
// them), rank 0 groups the removed voxels into objects, reports and stores: the report of one
// process, and three ranks' stored map is the one process's voxel for voxel.
TEST(MpiCli, DynamicOnRanksIsTheOneProcessDynamic) {
    const fs::path seq = Temp("mpi_dynamic_seq"), map = Temp("mpi_dynamic_map"),
                   one_map = Temp("mpi_dynamic_one");
    const std::string scene = std::string(STRATA_SOURCE_DIR) + "/datasets/scenes/traffic.json";
    // Under a sanitizer 5 sweeps in tiles of 6.4 m: the same paths at a quarter of the tiles
    // (85 s of ASan time with 8 sweeps in 3.2 m tiles on 2026-12-07).
    const bool sanitizer = strata::testing::UnderSanitizer();
    ASSERT_EQ(Strata("simulate --scene " + scene + " --out " + seq.string() + " --max-scans " +
                     (sanitizer ? "5" : "8") + " --no-picture")
                  .code,
              0);
    ASSERT_EQ(Strata("integrate " + map.string() + " --kitti " + seq.string() + " --tile-size " +
                     (sanitizer ? "6.4" : "3.2"))
                  .code,
              0);
    fs::remove_all(one_map);
    fs::copy(map, one_map, fs::copy_options::recursive);
    const Result one = Strata("dynamic " + one_map.string() + " --json --memory-budget 0");
    ASSERT_EQ(one.code, 0) << one.out;
    const nlohmann::json whole = ReportIn(one.out);
    ASSERT_GE(whole["objects"].size(), 2u) << one.out;
    for (int ranks : RankCounts()) {
        // Three ranks also store the static map: rank 0 alone commits it.
        // mpirun forwards a rank's stdout and stderr apart: the report alone on stdout.
        const std::string save = ranks == 2 ? " --no-save" : "";
        const fs::path err = Temp("mpi_dynamic_err.txt");
        const Result r = Shell("{ " + std::string(kMpirun) + " -n " + std::to_string(ranks) + " " +
                               STRATA_BINARY + " dynamic " + map.string() + save + " --json 2>" +
                               err.string() + "; }");
        const std::string said = ReadText(err);
        ASSERT_EQ(r.code, 0) << r.out << said;
        nlohmann::json report = ReportIn(r.out);
        report["map"] = whole["map"];
        EXPECT_EQ(report, whole) << ranks << " ranks";
        EXPECT_NE(said.find("tiles over " + std::to_string(ranks) + " ranks"), std::string::npos)
            << said;
    }
    ExpectSameStores(map, one_map);
    const Result check = Strata("check " + map.string());
    EXPECT_EQ(check.code, 0) << check.out;
}

// The pid of the process of rank `rank` running `strata integrate` on `map`, or -1.
pid_t RankPid(int rank, const fs::path& map) {
    const std::string wanted = "OMPI_COMM_WORLD_RANK=" + std::to_string(rank);
    for (const auto& e : fs::directory_iterator("/proc")) {
        const std::string name = e.path().filename().string();
        if (name.find_first_not_of("0123456789") != std::string::npos) continue;
        std::ifstream cmd(e.path() / "cmdline", std::ios::binary), env(e.path() / "environ");
        std::stringstream c, v;
        c << cmd.rdbuf();
        v << env.rdbuf();
        const std::string cmdline = c.str(), environ = v.str();
        if (cmdline.find(map.string()) == std::string::npos) continue;
        if (cmdline.rfind(STRATA_BINARY, 0) != 0) continue;
        if (environ.find(wanted + '\0') != std::string::npos) return std::stoi(name);
    }
    return -1;
}

TEST(MpiCli, AKilledRankFailsTheCommandAndLeavesTheLastCommit) {
    const fs::path small = MakeSequence(Temp("mpi_kill_first"), SequenceSpec{});
    SequenceSpec spec;
    spec.scans = 60;
    spec.points_per_scan = 40000;
    spec.room_half_m = Eigen::Vector3d(15.0, 10.0, 3.0);
    const fs::path large = MakeSequence(Temp("mpi_kill_seq"), spec);
    const fs::path map = Temp("mpi_kill_map");
    ASSERT_EQ(Strata("integrate " + map.string() + " --kitti " + small.string() +
                     " --voxel 0.05 --tile-size 3.2")
                  .code,
              0);
    const auto before = MapFiles(map);
    const fs::path log_file = Temp("mpi_kill.log");  // Temp() empties the path: once
    const std::string cmd = std::string(kMpirun) + " -n 2 " + STRATA_BINARY + " integrate " +
                            map.string() + " --kitti " + large.string() + " > " +
                            log_file.string() + " 2>&1";
    int status = 0;
    std::thread run([&] { status = std::system(cmd.c_str()); });
    // Rank 1 is killed once it has started integrating.
    pid_t victim = -1;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while ((victim = RankPid(1, map)) < 0 && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ASSERT_GT(victim, 0) << "rank 1 never started";
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    const bool killed = ::kill(victim, SIGKILL) == 0;
    run.join();
    const std::string log = ReadText(log_file);
    std::printf("[ mpi ] rank 1 (pid %d) %s:\n%s\n", victim, killed ? "killed" : "had ended",
                log.c_str());
    ASSERT_TRUE(killed) << "rank 1 finished before it could be killed; make the sequence longer";
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0) << "mpirun status " << status;
    EXPECT_NE(log.find("rank 1"), std::string::npos) << log;  // mpirun names the rank
    // The map is at its last commit: one session, its files as they were, and it checks clean.
    const store::MapStore after = store::MapStore::Open(map, store::MapStore::Access::kRead);
    EXPECT_EQ(after.Latest().sessions.size(), 1u);
    const auto now = MapFiles(map);
    for (const auto& [file, bytes] : before) {
        ASSERT_TRUE(now.count(file)) << file;
        EXPECT_EQ(now.at(file), bytes) << file;
    }
    const Result check = Strata("check " + map.string());
    EXPECT_EQ(check.code, 0) << check.out;
    // And the next command works.
    EXPECT_EQ(Strata("integrate " + map.string() + " --kitti " + small.string()).code, 0);
}

}  // namespace
}  // namespace strata::tools::test
