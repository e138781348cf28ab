// Moving things out of a stored map (docs/dynamic.md), on a street with a known answer: a sensor
// drives along flat ground between two facades while a box drives the other way. Every point
// that hit the box is dynamic, every other one static.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <set>

#include "MapDiff.hpp"
#include "PipelineTestUtil.hpp"
#include "Sanitizer.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/pipeline/Dynamic.hpp"
#include "strata/pipeline/MapAccess.hpp"
#include "strata/pipeline/NewSession.hpp"

// Its own namespace: the use-case tests are compiled in unity batches.
namespace strata::pipeline::test::dynamic_street {
namespace {

constexpr double kVoxel = 0.2;
constexpr double kSensorHeight = 1.8;
constexpr double kFacadeY = 8.0;
constexpr double kFacadeHeight = 6.0;
// Tolerances, at most 3x the losses measured (in the tests).
constexpr double kMinStaticKept = 0.999;  // SA (measured 1.0000)
constexpr double kMinDynamicRemoved =
    0.97;  // DA (measured 0.9878; 0.9886 removing scattered voxels)
constexpr double kMaxStaticRemoved = 0.0003;  // of the occupied voxels (measured 0)

// One scan of the street: points in the sensor frame, and which of them hit the box.
struct StreetScan {
    core::Scan scan;
    std::vector<bool> on_box;
};

// Nearest t > 0 of the ray o + t d into the box (slabs), or infinity.
double HitBox(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::AlignedBox3d& box) {
    constexpr double kNever = std::numeric_limits<double>::infinity();
    double t0 = 0.0, t1 = kNever;
    for (int a = 0; a < 3; ++a) {
        if (std::abs(d[a]) < 1e-12) {
            if (o[a] < box.min()[a] || o[a] > box.max()[a]) return kNever;
            continue;
        }
        double near = (box.min()[a] - o[a]) / d[a], far = (box.max()[a] - o[a]) / d[a];
        if (near > far) std::swap(near, far);
        t0 = std::max(t0, near), t1 = std::min(t1, far);
        if (t0 > t1) return kNever;
    }
    return t0 > 0.0 ? t0 : kNever;
}

// 40 beams from -24.1 to +2.1 degrees (none level: the box's top and the sensor share no voxel
// boundary), every 0.5 degrees around, 60 m range, 1 cm of range noise.
StreetScan CastScan(const Eigen::Vector3d& sensor, const std::optional<Eigen::AlignedBox3d>& box,
                    uint32_t seed) {
    StreetScan out;
    out.scan.T_world_sensor = Eigen::Isometry3d::Identity();
    out.scan.T_world_sensor.translation() = sensor;
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.01);
    for (int b = 0; b < 40; ++b) {
        const double el = (-24.1 + 26.2 * b / 39.0) * M_PI / 180.0;
        for (int a = 0; a < 720; ++a) {
            const double az = a * 0.5 * M_PI / 180.0;
            const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                    std::sin(el));
            double t = std::numeric_limits<double>::infinity();
            if (d.z() < 0.0) t = -sensor.z() / d.z();  // ground
            if (std::abs(d.y()) > 1e-9) {              // facades
                const double tf = ((d.y() > 0 ? kFacadeY : -kFacadeY) - sensor.y()) / d.y();
                if (sensor.z() + tf * d.z() < kFacadeHeight) t = std::min(t, tf);
            }
            const double tb = box ? HitBox(sensor, d, *box) : t;
            const bool on_box = tb < t;
            t = std::min(t, tb);
            if (!(t < 60.0)) continue;
            out.scan.points.push_back(d * (t + noise(rng)));
            out.on_box.push_back(on_box);
        }
    }
    return out;
}

// A street of `scans` scans: the sensor drives +x at 1 m a scan, the box (a car, 0.3 m above the
// ground) drives -x at `box_step` m a scan in the other lane (0: parked).
std::vector<StreetScan> Street(int scans, double box_step) {
    std::vector<StreetScan> out;
    for (int k = 0; k < scans; ++k) {
        const Eigen::Vector3d sensor(k * 1.0, 0.0, kSensorHeight);
        const double x = 35.0 - k * box_step;
        const Eigen::AlignedBox3d car(Eigen::Vector3d(x - 2.25, 2.65, 0.3),
                                      Eigen::Vector3d(x + 2.25, 4.45, 1.65));
        out.push_back(CastScan(sensor, car, static_cast<uint32_t>(k + 1)));
    }
    return out;
}

fs::path Integrate(const std::string& name, const std::vector<StreetScan>& scans,
                   double tile_size_m = store::StoreSettings{}.tile_size_m) {
    const fs::path dir = Temp(name);
    store::StoreSettings settings;
    settings.voxel_size_m = kVoxel;
    settings.tile_size_m = tile_size_m;
    store::MapStore map = store::MapStore::Create(dir, settings);
    store::SessionOptions options;
    options.name = "drive";
    NewSession session(map, settings.integration, options);
    for (const StreetScan& s : scans) (void)session.Integrate(s.scan);
    (void)session.Commit();
    return dir;
}

// Shares of the static points kept and of the box's points removed, as the dynamic-removal
// benchmark scores them: a point is kept when its voxel is occupied in the output map.
struct Scores {
    double static_accuracy = 0.0;   // SA
    double dynamic_accuracy = 0.0;  // DA
};

Scores Score(const std::vector<StreetScan>& scans, const core::VoxelMap& map) {
    const auto occ = map.occupancy->getConstAccessor();
    size_t statics = 0, kept = 0, dynamics = 0, removed = 0;
    for (const StreetScan& s : scans) {
        for (size_t i = 0; i < s.scan.points.size(); ++i) {
            // Beyond the integration's range no map holds a point: not scored.
            if (s.scan.points[i].norm() > integration::IntegrationConfig{}.max_range_m) continue;
            const Eigen::Vector3d p = s.scan.T_world_sensor * s.scan.points[i];
            const openvdb::Coord c(static_cast<int>(std::floor(p.x() / kVoxel)),
                                   static_cast<int>(std::floor(p.y() / kVoxel)),
                                   static_cast<int>(std::floor(p.z() / kVoxel)));
            const bool occupied = occ.getValue(c) > 0.0F;
            if (s.on_box[i]) {
                ++dynamics, removed += occupied ? 0 : 1;
            } else {
                ++statics, kept += occupied ? 1 : 0;
            }
        }
    }
    return {static_cast<double>(kept) / static_cast<double>(statics),
            dynamics ? static_cast<double>(removed) / static_cast<double>(dynamics) : 1.0};
}

TEST(PipelineDynamic, ACarDrivingPastIsRemovedAndTheErodedGroundKept) {
    const std::vector<StreetScan> scans = Street(30, 1.0);
    const fs::path dir = Integrate("dynamic_street", scans);
    store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kWrite);
    const store::Snapshot raw = map.Latest();
    const Scores before = Score(scans, map.LoadMap(raw));
    DynamicOutcome outcome = FindDynamic(map, raw, dynamic::DynamicConfig{});
    const Scores after = Score(scans, outcome.cleaned);
    std::printf(
        "raw map SA %.4f DA %.4f; static map SA %.4f DA %.4f; %zu objects, %zu removed, "
        "%zu restored\n",
        before.static_accuracy, before.dynamic_accuracy, after.static_accuracy,
        after.dynamic_accuracy, outcome.result.objects.size(), outcome.result.removed_voxels(),
        outcome.result.restored_voxels());
    // Measured 2026-12-06: SA 0.8495 -> 1.0000, DA 0.9999 -> 0.9878; four objects, all in the
    // car's lane, the largest most of the removed voxels.
    EXPECT_GE(after.static_accuracy, kMinStaticKept);
    EXPECT_GE(after.dynamic_accuracy, kMinDynamicRemoved);
    EXPECT_GT(after.static_accuracy, before.static_accuracy + 0.1) << "the ground the rays eroded";
    size_t largest = 0;
    for (const dynamic::MovingObject& o : outcome.result.objects) {
        largest = std::max(largest, o.voxels);
        EXPECT_GE(o.box.min().y(), 2.6 - kVoxel) << "in the car's lane";
        EXPECT_LE(o.box.max().y(), 4.45 + kVoxel);
        EXPECT_LE(o.box.max().z(), 1.65 + kVoxel);
    }
    EXPECT_GE(static_cast<double>(largest),
              0.6 * static_cast<double>(outcome.result.removed_voxels()))
        << "the trail";

    const size_t objects = outcome.result.objects.size();
    const int64_t commit = StoreDynamic(map, outcome);
    EXPECT_EQ(map.Latest().commit, commit);
    EXPECT_EQ(map.ProductRows("dynamic").size(), objects);
    const Scores stored = Score(scans, map.LoadMap(map.Latest()));
    EXPECT_EQ(stored.static_accuracy, after.static_accuracy) << "the static map as stored";
    const Scores as_of = Score(scans, map.LoadMap(SelectSnapshot(map, "drive")));
    EXPECT_EQ(as_of.static_accuracy, before.static_accuracy) << "--as-of: the raw map";
    // The removed voxels are of class dynamic.
    const auto label = map.LoadMap(map.Latest()).label;
    size_t dynamic_voxels = 0;
    for (auto on = label->cbeginValueOn(); on; ++on) {
        if (*on == static_cast<int32_t>(core::SemanticClass::kDynamic)) ++dynamic_voxels;
    }
    EXPECT_EQ(dynamic_voxels, outcome.result.removed_voxels());
}

TEST(PipelineDynamic, AStaticStreetLosesAlmostNothing) {
    const std::vector<StreetScan> scans = Street(30, 0.0);
    const fs::path dir = Integrate("dynamic_static", scans);
    const store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kRead);
    const DynamicOutcome outcome = FindDynamic(map, map.Latest(), dynamic::DynamicConfig{});
    std::printf("%zu of %zu occupied voxels removed\n", outcome.result.removed_voxels(),
                outcome.result.occupied);
    // Measured 2026-12-06: 0 of 51029; the issue asks for < 0.1 %.
    EXPECT_LT(static_cast<double>(outcome.result.removed_voxels()),
              kMaxStaticRemoved * static_cast<double>(outcome.result.occupied));
    EXPECT_GE(Score(scans, outcome.cleaned).static_accuracy, kMinStaticKept);
}

// A map larger than the memory budget is judged a tile at a time: the street in tiles of
// 6.4 m (84 of them; the car's trail crosses several), with a budget just below what reading
// it whole takes. What is found, and the static map stored, equal the whole map's voxel for voxel.
TEST(PipelineDynamic, TileByTileFindsAndStoresWhatTheWholeMapDoes) {
    // Under a sanitizer 12 scans: the trail crosses two tiles (33 s of ASan time with 30 scans).
    const int scans = strata::testing::UnderSanitizer() ? 12 : 30;
    const fs::path whole_dir = Integrate("dynamic_tiles_whole", Street(scans, 1.0), 6.4);
    const fs::path tiled_dir = Temp("dynamic_tiles_tiled");
    fs::remove_all(tiled_dir);
    fs::copy(whole_dir, tiled_dir, fs::copy_options::recursive);
    store::MapStore whole_map = store::MapStore::Open(whole_dir, store::MapStore::Access::kWrite);
    store::MapStore tiled_map = store::MapStore::Open(tiled_dir, store::MapStore::Access::kWrite);
    const store::Snapshot snapshot = tiled_map.Latest();
    size_t budget = size_t{1} << 30;
    while (DynamicReadsWhole(tiled_map, snapshot, budget)) budget = budget * 9 / 10;
    DynamicOutcome whole = FindDynamic(whole_map, whole_map.Latest(), dynamic::DynamicConfig{});
    DynamicOutcome tiled = FindDynamic(tiled_map, snapshot, dynamic::DynamicConfig{}, "", budget);
    std::printf("%zu tiles within %.2f MB; %zu objects, %zu removed, %zu restored\n", tiled.tiles,
                static_cast<double>(budget) / 1e6, tiled.result.objects.size(),
                tiled.result.removed_voxels(), tiled.result.restored_voxels());
    EXPECT_EQ(whole.tiles, 0U);
    ASSERT_GT(tiled.tiles, 50U);
    const dynamic::DynamicResult &t = tiled.result, &w = whole.result;
    ASSERT_GT(w.objects.size(), 0U);
    EXPECT_EQ(t.candidates, w.candidates);
    EXPECT_EQ(t.removed_occupied, w.removed_occupied);
    EXPECT_EQ(t.scattered, w.scattered);
    EXPECT_EQ(t.occupied, w.occupied);
    EXPECT_EQ(t.static_voxels, w.static_voxels);
    ASSERT_EQ(t.objects.size(), w.objects.size());
    for (size_t k = 0; k < w.objects.size(); ++k) {
        EXPECT_EQ(t.objects[k].id, w.objects[k].id);
        EXPECT_EQ(t.objects[k].voxels, w.objects[k].voxels);
        EXPECT_EQ(t.objects[k].box.min(), w.objects[k].box.min());
        EXPECT_EQ(t.objects[k].box.max(), w.objects[k].box.max());
    }
    EXPECT_EQ(tiled.object_sessions, whole.object_sessions);
    EXPECT_EQ(strata::testing::FirstDifference("removed", *t.removed, *w.removed), "");
    EXPECT_EQ(strata::testing::FirstDifference("restored", *t.restored, *w.restored), "");
    // The trail (the largest object) crosses tiles: its voxels were judged in several.
    const auto trail =
        std::max_element(t.objects.begin(), t.objects.end(),
                         [](const auto& a, const auto& b) { return a.voxels < b.voxels; });
    const store::MapSettings& settings = tiled_map.settings();
    std::set<std::pair<int, int>> trail_tiles;
    for (auto on = t.removed->cbeginValueOn(); on; ++on) {
        if (*on != trail->id) continue;
        const store::TileKey key = settings.TileOf(on.getCoord());
        trail_tiles.insert({key.x, key.y});
    }
    EXPECT_GT(trail_tiles.size(), 1U);

    (void)StoreDynamic(whole_map, whole);
    (void)StoreDynamic(tiled_map, tiled);
    EXPECT_EQ(strata::testing::MapDifference(tiled_map.LoadMap(tiled_map.Latest()),
                                             whole_map.LoadMap(whole_map.Latest())),
              "");
    EXPECT_EQ(tiled_map.ProductRows("dynamic").size(), w.objects.size());

    // A budget below one tile with its neighbours' layers is refused, naming the flag.
    const MapState before = StateOf(tiled_dir, "dynamic");
    try {
        (void)FindDynamic(tiled_map, tiled_map.Latest(), dynamic::DynamicConfig{}, "", 1000);
        ADD_FAILURE() << "a 1 kB budget was accepted";
    } catch (const RefusedError& e) {
        EXPECT_NE(std::string(e.what()).find("raise --memory-budget"), std::string::npos)
            << e.what();
    }
    EXPECT_EQ(StateOf(tiled_dir, "dynamic"), before);
}

TEST(PipelineDynamic, StoringFromAReaderOrAnUnknownSessionIsRefused) {
    const fs::path dir = Integrate("dynamic_refused", Street(6, 1.0));
    const MapState before = StateOf(dir, "dynamic");
    store::MapStore reader = store::MapStore::Open(dir, store::MapStore::Access::kRead);
    DynamicOutcome outcome = FindDynamic(reader, reader.Latest(), dynamic::DynamicConfig{});
    EXPECT_THROW((void)StoreDynamic(reader, outcome), InvalidArgumentError);
    EXPECT_THROW((void)FindDynamic(reader, reader.Latest(), {}, "no-such-session"), NotFoundError);
    dynamic::DynamicConfig bad;
    bad.margin_voxels = -1;
    EXPECT_THROW((void)FindDynamic(reader, reader.Latest(), bad), InvalidArgumentError);
    EXPECT_EQ(StateOf(dir, "dynamic"), before);
}

}  // namespace
}  // namespace strata::pipeline::test::dynamic_street
