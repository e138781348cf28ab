// `strata register` and `strata integrate --align` through the program, on the simulated
// street: the second half of a drive, recorded in a frame moved by a known transform, is found;
// a guess far off is refused and leaves the map as it was.
#include <gtest/gtest.h>
#include <unistd.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "CliTestUtil.hpp"
#include "RealData.hpp"
#include "RealPairs.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::tools::test {
namespace {

using nlohmann::json;

// Exit codes of the kinds of error (tools/strata/Main.cpp).
constexpr int kExitUsage = 2, kExitRefused = 4, kExitNotFound = 5;
// Simulated scans (2 cm range noise), half a street of overlap: measured 3.9 mm / 0.008 deg
// (register and integrate --align alike).
constexpr double kTranslationTolM = 0.01;
constexpr double kRotationTolDeg = 0.02;
// The frame the second session was recorded in: x, y, z, yaw.
constexpr double kMoveX = 1.2, kMoveY = -0.8, kMoveZ = 0.2, kMoveYawDeg = 6.0;

Eigen::Isometry3d Move() {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() =
        Eigen::AngleAxisd(kMoveYawDeg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(kMoveX, kMoveY, kMoveZ);
    return T;
}

struct Street {
    fs::path seq;    // the simulated drive, world frame
    fs::path moved;  // the same scans, poses in a frame moved by Move()
    fs::path map;    // frames 0-5 integrated
};

const Street& StreetData() {
    static const Street street = [] {
        Street s;
        s.seq = Temp("register_seq");
        s.moved = Temp("register_moved");
        s.map = Temp("register_map");
        const std::string scene = std::string(STRATA_SOURCE_DIR) + "/datasets/scenes/street.json";
        const Result sim = Strata("simulate --scene " + scene + " --out " + s.seq.string() +
                                  " --max-scans 12 --no-picture");
        EXPECT_EQ(sim.code, 0) << sim.out;
        fs::create_directories(s.moved);
        fs::create_directory_symlink(fs::absolute(s.seq / "velodyne"), s.moved / "velodyne");
        for (const char* f : {"calib.txt", "times.txt"}) {
            if (fs::exists(s.seq / f)) fs::copy_file(s.seq / f, s.moved / f);
        }
        std::vector<Eigen::Isometry3d> poses;
        for (const auto& p : io::ReadPoseFile(s.seq / "poses.txt")) {
            poses.push_back(Move().inverse() * p.T);
        }
        io::WriteKittiPoses(s.moved / "poses.txt", poses);
        const Result integrate =
            Strata("integrate " + s.map.string() + " --kitti " + s.seq.string() + " --frames 0:6");
        EXPECT_EQ(integrate.code, 0) << integrate.out;
        return s;
    }();
    return street;
}

fs::path CopyOfMap(const std::string& name) {
    const fs::path dir = Temp(name);
    fs::copy(StreetData().map, dir, fs::copy_options::recursive);
    return dir;
}

// Translation (m) and rotation (deg) between two transforms.
std::pair<double, double> Difference(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
    const Eigen::Matrix4d d = a.inverse() * b;
    return {d.block<3, 1>(0, 3).norm(),
            Eigen::AngleAxisd(Eigen::Matrix3d(d.block<3, 3>(0, 0))).angle() * 180.0 / M_PI};
}

Eigen::Matrix4d FromJson(const json& T) {
    Eigen::Matrix4d m;
    for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = T.at(static_cast<size_t>(i)).get<double>();
    return m;
}

TEST(RegistrationCli, FindsASessionRecordedInAMovedFrameWithTheFixedKeys) {
    const Street& s = StreetData();
    const Result r = Strata("register " + s.map.string() + " --kitti " + s.moved.string() +
                            " --frames 6:12 --json");
    ASSERT_EQ(r.code, 0) << r.out;
    const json j = json::parse(r.out.substr(r.out.find('{')));
    for (const char* key : {"T", "converged", "rmse_m", "overlap", "time_ms"}) {
        EXPECT_TRUE(j.contains(key)) << key;
    }
    ASSERT_EQ(j["T"].size(), 16u);
    EXPECT_TRUE(j["converged"].get<bool>());
    const auto [dt, dr] = Difference(FromJson(j["T"]), Move().matrix());
    RecordProperty("error_m", std::to_string(dt));
    RecordProperty("error_deg", std::to_string(dr));
    EXPECT_LT(dt, kTranslationTolM) << r.out;
    EXPECT_LT(dr, kRotationTolDeg) << r.out;
}

// Real data through the program: KITTI 00 frame 5 against a map of frame 0 (0.1 m), from a
// guess 0.5 m / 3 deg off the raw-point optimum (tests/support/RawIcp.hpp), which the library
// test measures in detail (RegistrationRealData.*).
TEST(RegistrationCli, RegistersAKitti00ScanOnTheRawPointOptimum) {
    using namespace registration::test;                  // NOLINT: the real-data references
    constexpr double kVsRawDeg = 0.03, kVsRawM = 0.005;  // measured 0.012 deg, 1.9 mm
    const fs::path dir = fs::path(STRATA_DATA_DIR) / "kitti00";
    STRATA_SKIP_WITHOUT_DATA(dir / "poses_sptam.txt");
    const Kitti00 k = LoadKitti00(dir);
    const RawOptimum::Result opt =
        RawOptimum(RangeFiltered(k.scans[0], 0.0, kMapMaxRangeM))
            .Align(RangeFiltered(k.scans[5], kScanMinRangeM, kScanMaxRangeM),
                   k.orbslam2[0].inverse() * k.orbslam2[5]);
    const fs::path map = Temp("register_kitti");
    ASSERT_EQ(Strata("integrate " + map.string() + " --kitti " + dir.string() +
                     " --frames 0:1 --voxel 0.1")
                  .code,
              0);
    const Eigen::Isometry3d guess = Off(opt.mean);
    const Eigen::Vector3d t = guess.translation();
    const Result r =
        Strata("register " + map.string() + " --kitti " + dir.string() + " --frames 5:6 --json" +
               " --init " + std::to_string(t.x()) + "," + std::to_string(t.y()) + "," +
               std::to_string(t.z()) + "," + std::to_string(registration::YawDeg(guess)));
    ASSERT_EQ(r.code, 0) << r.out;
    const json j = json::parse(r.out.substr(r.out.find('{')));
    const PoseGap g = Gap(opt.mean, Eigen::Isometry3d(FromJson(j["T"])));
    RecordProperty("vs_raw_m", std::to_string(g.m));
    RecordProperty("vs_raw_deg", std::to_string(g.deg));
    std::cout << "vs raw " << g.m << " m " << g.deg << " deg\n";
    EXPECT_LT(g.deg, kVsRawDeg) << r.out;
    EXPECT_LT(g.m, kVsRawM) << r.out;
}

TEST(RegistrationCli, RefusesAGuessFarOffAndSaysWhy) {
    const Street& s = StreetData();
    const auto before = MapFiles(s.map);
    const Result r = Strata("register " + s.map.string() + " --kitti " + s.seq.string() +
                            " --frames 6:12 --init 3,2,0,120");
    EXPECT_EQ(r.code, kExitRefused) << r.out;
    EXPECT_NE(r.out.find("refused"), std::string::npos) << r.out;
    EXPECT_EQ(MapFiles(s.map), before);  // a refused registration writes nothing
}

TEST(RegistrationCli, BadInputFailsNamingTheProblem) {
    const Street& s = StreetData();
    Result r = Strata("register " + s.map.string());
    EXPECT_EQ(r.code, kExitUsage);
    EXPECT_NE(r.out.find("--kitti"), std::string::npos) << r.out;
    r = Strata("register " + s.map.string() + " --kitti " + s.seq.string() + " --init 1,2,3");
    EXPECT_EQ(r.code, kExitUsage) << r.out;
    r = Strata("register " + Temp("no_such_map").string() + " --kitti " + s.seq.string());
    EXPECT_EQ(r.code, kExitNotFound);
    EXPECT_NE(r.out.find("no_such_map"), std::string::npos) << r.out;
}

TEST(RegistrationIntegrateAlignCli, StoresTheTransformAsTheSessionsAlignment) {
    const Street& s = StreetData();
    const fs::path map = CopyOfMap("align_ok");
    const Result r = Strata("integrate " + map.string() + " --kitti " + s.moved.string() +
                            " --frames 6:12 --align --name day2");
    ASSERT_EQ(r.code, 0) << r.out;
    const store::MapStore store = store::MapStore::Open(map, store::MapStore::Access::kRead);
    const store::Snapshot latest = store.Latest();
    ASSERT_EQ(latest.sessions.size(), 2u);
    const store::SessionRecord& day2 = latest.sessions.back();
    EXPECT_EQ(day2.name, "day2");
    const auto [dt, dr] = Difference(day2.alignment, Move().matrix());
    RecordProperty("error_m", std::to_string(dt));
    RecordProperty("error_deg", std::to_string(dr));
    EXPECT_LT(dt, kTranslationTolM);
    EXPECT_LT(dr, kRotationTolDeg);
    EXPECT_NE(day2.notes.find("rmse_m"), std::string::npos) << day2.notes;
}

// The voxels session `name` saw occupied (its layer file in every tile it touched).
openvdb::BoolGrid::Ptr SessionVoxels(const fs::path& map, const std::string& name) {
    const store::MapStore store = store::MapStore::Open(map, store::MapStore::Access::kRead);
    auto voxels = openvdb::BoolGrid::create(false);
    for (const store::LayerFile& file : store.SessionLayers(store.FindSession(name))) {
        const store::SessionLayer layer = store.ReadLayer(file);
        if (layer.occupied) voxels->tree().topologyUnion(layer.occupied->tree());
    }
    return voxels;
}

// |a and b| / |a or b| of two voxel sets.
double Jaccard(const openvdb::BoolGrid& a, const openvdb::BoolGrid& b) {
    auto in_b = b.getConstAccessor();
    size_t both = 0;
    for (auto it = a.cbeginValueOn(); it; ++it) both += in_b.isValueOn(it.getCoord()) ? 1 : 0;
    const double either = double(a.activeVoxelCount() + b.activeVoxelCount() - both);
    return either > 0.0 ? double(both) / either : 0.0;
}

// The reference is the same scans integrated at their true (simulated) poses: the aligned
// session's voxels must be those, not the moved frame's (the control, integrated without
// --align, shows how far apart they would be).
TEST(RegistrationIntegrateAlignCli, PutsTheSessionsVoxelsWhereItsTruePosesPutThem) {
    // Jaccard index with the reference's voxels, measured 0.972 aligned, 0.052 not aligned.
    constexpr double kMinAlignedJaccard = 0.92, kMaxUnalignedJaccard = 0.15;
    const Street& s = StreetData();
    const fs::path aligned = CopyOfMap("align_voxels");
    const fs::path truth = CopyOfMap("align_truth");
    const fs::path unaligned = CopyOfMap("align_none");
    const std::string frames = " --frames 6:12 --name day2";
    ASSERT_EQ(Strata("integrate " + aligned.string() + " --kitti " + s.moved.string() + frames +
                     " --align")
                  .code,
              0);
    ASSERT_EQ(Strata("integrate " + truth.string() + " --kitti " + s.seq.string() + frames).code,
              0);
    ASSERT_EQ(
        Strata("integrate " + unaligned.string() + " --kitti " + s.moved.string() + frames).code,
        0);
    const openvdb::BoolGrid::Ptr reference = SessionVoxels(truth, "day2");
    ASSERT_GT(reference->activeVoxelCount(), 1000u);
    const double j_aligned = Jaccard(*SessionVoxels(aligned, "day2"), *reference);
    const double j_unaligned = Jaccard(*SessionVoxels(unaligned, "day2"), *reference);
    RecordProperty("jaccard_aligned", std::to_string(j_aligned));
    RecordProperty("jaccard_unaligned", std::to_string(j_unaligned));
    std::cout << "jaccard aligned " << j_aligned << " unaligned " << j_unaligned << "\n";
    EXPECT_GT(j_aligned, kMinAlignedJaccard);
    EXPECT_LT(j_unaligned, kMaxUnalignedJaccard);
}

TEST(RegistrationIntegrateAlignCli, ARefusedAlignmentCommitsNothing) {
    const Street& s = StreetData();
    const fs::path map = CopyOfMap("align_refused");
    const auto before = MapFiles(map);
    const Result r = Strata("integrate " + map.string() + " --kitti " + s.moved.string() +
                            " --frames 6:12 --align --init 3,2,0,120");
    EXPECT_EQ(r.code, kExitRefused) << r.out;
    EXPECT_NE(r.out.find("refused"), std::string::npos) << r.out;
    EXPECT_EQ(MapFiles(map), before);
    const store::MapStore store = store::MapStore::Open(map, store::MapStore::Access::kRead);
    EXPECT_EQ(store.Latest().sessions.size(), 1u);
}

TEST(RegistrationIntegrateAlignCli, NeedsAnExistingMap) {
    const Street& s = StreetData();
    const fs::path map = Temp("align_new");
    const Result r =
        Strata("integrate " + map.string() + " --kitti " + s.seq.string() + " --align");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.out.find("--align"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(map));
}

}  // namespace
}  // namespace strata::tools::test
