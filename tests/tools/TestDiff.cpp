// `strata diff` through the program: a room mapped twice, the second time with a pillar in it.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "CliTestUtil.hpp"
#include "strata/core/GridTypes.hpp"
#include "strata/io/Image.hpp"

namespace strata::tools::test {
namespace {

using nlohmann::json;

// The pillar of the second drive: x 1.0-1.6 m, y -1.6 to -1.0 m, floor to ceiling.
const Eigen::Vector3d kPillarMin(1.0, -1.6, -1.5), kPillarMax(1.6, -1.0, 1.5);
// Centroids and boxes are voxel-quantised and only the faces the sensor saw are occupied.
constexpr double kCentroidTol = 0.5;

// Distance along the ray o + t d to the box [lo, hi], or infinity when it misses (slab test).
double RayBox(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& lo,
              const Eigen::Vector3d& hi) {
    double t0 = 0.0, t1 = INFINITY;
    for (int k = 0; k < 3; ++k) {
        const double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
        t0 = std::max(t0, std::min(a, b));
        t1 = std::min(t1, std::max(a, b));
    }
    return t0 <= t1 ? t0 : INFINITY;
}

// A KITTI sequence of a 6 x 5 x 3 m room seen from three poses, optionally with the pillar.
fs::path MakeRoom(const fs::path& dir, bool pillar) {
    fs::remove_all(dir);
    fs::create_directories(dir / "velodyne");
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Eigen::Vector3d half(3.0, 2.5, 1.5);
    std::vector<Eigen::Isometry3d> poses;
    for (int k = 0; k < 3; ++k) {
        Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
        T.translation() = Eigen::Vector3d(-1.0 + 0.5 * k, 0.3, 0.0);
        poses.push_back(T);
        std::vector<Eigen::Vector3d> points;
        while (points.size() < 20000) {
            // z, y, x, one draw each: argument order is unspecified (gcc right to left, clang
            // left to right) and the scan must not depend on the compiler; gcc's order is kept.
            Eigen::Vector3d d;
            d.z() = u(rng);
            d.y() = u(rng);
            d.x() = u(rng);
            d.normalize();
            const Eigen::Vector3d o = T.translation();
            double t = INFINITY;  // to the room's walls (the room is centred on the origin)
            for (int a = 0; a < 3; ++a) {
                t = std::min(t, ((d[a] > 0 ? half[a] : -half[a]) - o[a]) / d[a]);
            }
            if (pillar) t = std::min(t, RayBox(o, d, kPillarMin, kPillarMax));
            points.push_back(d * t);  // sensor frame: no rotation
        }
        char name[32];
        std::snprintf(name, sizeof(name), "%06d.bin", k);
        io::WriteKittiBin(dir / "velodyne" / name, points);
    }
    io::WriteKittiPoses(dir / "poses.txt", poses);
    return dir;
}

// Scratch paths of the running test (CTest runs the tests of this file in parallel).
fs::path Scratch(const std::string& what) {
    return Temp(std::string("diff_") +
                ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" + what);
}

struct Room {
    fs::path map = Scratch("map");
    fs::path empty = MakeRoom(Scratch("empty"), false);
    fs::path pillar = MakeRoom(Scratch("pillar"), true);

    Room() {
        EXPECT_EQ(Strata("integrate " + map.string() + " --voxel 0.1 --name empty --kitti " +
                         empty.string())
                      .code,
                  0);
        EXPECT_EQ(
            Strata("integrate " + map.string() + " --name pillar --kitti " + pillar.string()).code,
            0);
    }
};

json Diff(const std::string& args) {
    const Result r = Strata("diff " + args + " --json");
    EXPECT_EQ(r.code, 0) << r.out;
    return r.code == 0 ? json::parse(r.out) : json::object();
}

void ExpectPillar(const json& object, const char* kind) {
    EXPECT_EQ(object.at("kind"), kind);
    const Eigen::Vector3d centre = 0.5 * (kPillarMin + kPillarMax);
    for (int k = 0; k < 2; ++k) {
        EXPECT_NEAR(object.at("centroid")[k].get<double>(), centre[k], kCentroidTol);
    }
    for (const char* key : {"id", "voxels", "volume_m3", "bbox_min", "bbox_max", "class"}) {
        EXPECT_TRUE(object.contains(key)) << key;
    }
}

TEST(Diff, SessionsReportThePillarAddedAndRemoved) {
    const Room room;
    const json forward = Diff(room.map.string() + " --from empty --to pillar");
    ASSERT_EQ(forward.at("objects").size(), 1u) << forward.dump(1);
    ExpectPillar(forward["objects"][0], "added");
    EXPECT_TRUE(forward.contains("unknown_voxels"));
    const json backward = Diff(room.map.string() + " --from 2 --to 1");
    ASSERT_EQ(backward.at("objects").size(), 1u) << backward.dump(1);
    ExpectPillar(backward["objects"][0], "removed");
    // The pillar's far side and the wall behind it: seen by one drive only, never a change.
    EXPECT_GT(forward.at("unknown_voxels").get<size_t>(), 0u);

    const json same = Diff(room.map.string() + " --from map@1 --to map@1");
    EXPECT_EQ(same.at("objects").size(), 0u);
    EXPECT_EQ(same.at("unknown_voxels"), 0);
}

TEST(Diff, FiltersRegionAndClass) {
    const Room room;
    const std::string sides = room.map.string() + " --from 1 --to 2";
    EXPECT_EQ(Diff(sides + " --region -3,0,3,3").at("objects").size(), 0u);  // north half
    EXPECT_EQ(Diff(sides + " --region 0,-3,3,0").at("objects").size(), 1u);
    EXPECT_EQ(Diff(sides + " --class vehicle").at("objects").size(), 0u);  // unlabelled room
    EXPECT_EQ(Diff(sides + " --min-voxels 100000").at("objects").size(), 0u);
}

TEST(Diff, UncommittedScansAgainstTheMap) {
    const Room room;
    const fs::path map = Scratch("uncommitted");
    const fs::path& empty = room.empty;
    const fs::path& pillar = room.pillar;
    ASSERT_EQ(Strata("integrate " + map.string() + " --voxel 0.1 --kitti " + empty.string()).code,
              0);
    const auto before = MapFiles(map);
    const json j = Diff(map.string() + " --to-kitti " + pillar.string());
    ASSERT_EQ(j.at("objects").size(), 1u) << j.dump(1);
    ExpectPillar(j["objects"][0], "added");
    EXPECT_EQ(MapFiles(map), before);  // a query never writes tiles
}

TEST(Diff, WritesVdbAndPngAndSavesTheResult) {
    const Room room;
    const fs::path out = Scratch("out");
    fs::create_directories(out);
    const Result r = Strata("diff " + room.map.string() + " --from 1 --to 2 --save --vdb " +
                            (out / "c.vdb").string() + " --png " + (out / "c.png").string());
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("saved as change set 1"), std::string::npos) << r.out;

    openvdb::initialize();
    openvdb::io::File file((out / "c.vdb").string());
    file.open();
    const auto added = openvdb::gridPtrCast<openvdb::BoolGrid>(file.readGrid("added"));
    const auto removed = openvdb::gridPtrCast<openvdb::BoolGrid>(file.readGrid("removed"));
    ASSERT_TRUE(added && removed);
    EXPECT_GT(added->activeVoxelCount(), 0u);
    EXPECT_EQ(removed->activeVoxelCount(), 0u);

    const io::RgbImage png = io::ReadPng(out / "c.png");
    size_t green = 0;
    for (int y = 0; y < png.height(); ++y) {
        for (int x = 0; x < png.width(); ++x) {
            const core::Rgb c = png.At(x, y);
            green += (c.g > 150 && c.r < 50 && c.b < 50) ? 1 : 0;
        }
    }
    EXPECT_GT(green, 0u);

    const Result list = Strata("diff " + room.map.string() + " --list --json");
    ASSERT_EQ(list.code, 0) << list.out;
    const json sets = json::parse(list.out);
    ASSERT_EQ(sets.size(), 1u);
    EXPECT_EQ(sets[0].at("from"), "session 1");
    EXPECT_EQ(sets[0].at("objects"), 1);
    EXPECT_EQ(sets[0].at("report").at("objects").size(), 1u);
}

TEST(Diff, BadQueriesFailWithAMessageAndLeaveTheMapAlone) {
    const Room room;
    const auto before = MapFiles(room.map);
    const std::string map = room.map.string();
    const struct {
        std::string args;
        int code;
        std::string message;
    } cases[] = {
        {map + " --from 1 --to 9", kNotFound, "no session"},
        {map + " --from 1 --to nobody", kNotFound, "nobody"},
        {map + " --from 1", kUsage, "--to"},
        {map + " --from 1 --to 2 --region 1,2,3", kUsage, "region"},
        {map + " --from 1 --to 2 --class spaceship", kUsage, "spaceship"},
        {map + " --from 1 --to 2 --png /nonexistent/dir/c.png", kFailed, "/nonexistent/dir/c.png"},
        {Temp("diff_nomap").string() + " --from 1 --to 2", kNotFound, "diff_nomap"},
    };
    for (const auto& c : cases) {
        EXPECT_TRUE(FailedWith(Strata("diff " + c.args), c.code, c.message)) << c.args;
    }
    EXPECT_EQ(MapFiles(room.map), before);
    EXPECT_EQ(Strata("diff " + map + " --list").code, 0);
}

}  // namespace
}  // namespace strata::tools::test
