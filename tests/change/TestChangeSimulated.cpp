// Change detection scored against the simulator's ground truth: the street recorded twice
// (datasets/scenes/street_two_sessions.json: cars moved, left and arrived, a container placed, a
// wall cut, a bush grown). Prints the per-edit table docs/change.md shows.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <set>

#include "ChangeEval.hpp"
#include "TempPath.hpp"
#include "strata/change/ChangeDetection.hpp"
#include "strata/change/MapObserver.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/sim/SimulateScene.hpp"
#include "strata/store/SessionWriter.hpp"

namespace strata::change::simulated_tests {
namespace {

namespace fs = std::filesystem;
using openvdb::BoolGrid;

constexpr double kVoxel = 0.2;
// The targets.
constexpr double kMinPrecision = 0.95;
constexpr double kMinRecall = 0.95;
constexpr double kMinIoU = 0.9;

using testing::ChangeCase;
using testing::ChangeScore;

// Simulates the scene once per test binary, integrates both sessions into a store and reads the
// two sessions' layers back.
const ChangeCase& Scene() {
    static const fs::path temp = strata::test::TempPath("change_sim");
    static const ChangeCase scene = [] {
        ChangeCase s;
        s.voxel = kVoxel;
        fs::remove_all(temp);
        const fs::path scene_file =
            fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/street_two_sessions.json";
        sim::SimulateConfig config;
        config.write_picture = false;
        (void)sim::SimulateSceneToSequence(scene_file, temp / "sim", config);
        s.edits = testing::ReadTruthEdits(temp / "sim/session_1/ground_truth.json");
        std::set<int> objects;
        for (const testing::TruthEdit& e : s.edits) objects.insert(e.object);

        store::StoreSettings settings;
        settings.voxel_size_m = kVoxel;
        store::MapStore map = store::MapStore::Create(temp / "map", settings);
        std::vector<int64_t> sessions;
        for (const char* session : {"session_0", "session_1"}) {
            const io::KittiSequence seq = io::OpenKittiSequence(temp / "sim" / session);
            store::SessionWriter writer(map, integration::IntegrationConfig{}, {});
            for (size_t i = 0; i < seq.size(); ++i) writer.Integrate(io::ReadKittiScan(seq, i));
            sessions.push_back(writer.Commit().id);
            (session == std::string("session_0") ? s.hits_a : s.hits_b) =
                testing::ReadSessionHits(seq, objects, kVoxel);
        }
        MapObserver observer(map);
        s.a = observer.Session(sessions[0]);
        s.b = observer.Session(sessions[1]);
        return s;
    }();
    return scene;
}

TEST(ChangeSimulated, StreetTwoSessionsMatchesTheEdits) {
    const ChangeCase& s = Scene();
    const ChangeScore score =
        testing::ScoreChanges(s, ChangeQuery{}, /*strict=*/false, /*table=*/true);
    const ChangeScore strict =
        testing::ScoreChanges(s, ChangeQuery{}, /*strict=*/true, /*table=*/false);
    std::printf(
        "[ change ] objects %zu, precision %.3f, recall %.3f (%zu observable edits), "
        "pooled voxel IoU %.3f (strict %.3f)\n",
        score.objects, score.precision, score.recall, score.observable, score.iou, strict.iou);
    EXPECT_EQ(score.observable, s.edits.size()) << "every edit is in view of both drives";
    EXPECT_GE(score.precision, kMinPrecision);
    EXPECT_GE(score.recall, kMinRecall);
    EXPECT_GE(score.iou, kMinIoU);
    EXPECT_GE(strict.iou, kMinIoU);
}

// What each safeguard of the query buys (docs/change.md prints this table, and its text claims
// what the asserts hold: each safeguard alone leaves many false objects, both leave the seven
// edits, growth gives back IoU, the support rule changes nothing here, a wider margin costs IoU).
TEST(ChangeSimulated, Ablation) {
    const ChangeCase& s = Scene();
    std::printf(
        "[ change ] | surface tolerance | observed margin | grow | support depth | "
        "objects | precision | recall | IoU | IoU (strict) |\n");
    struct Row {
        int tolerance, margin, grow, support;
        size_t objects;  // measured 2026-12-02 (docs/change.md)
        double precision, recall, iou, strict_iou;
    };
    const Row rows[] = {
        {0, 0, 0, 0, 229, 0.017, 0.571, 0.946, 0.911}, {1, 0, 0, 0, 69, 0.101, 1.0, 0.824, 0.854},
        {0, 1, 0, 0, 94, 0.074, 1.0, 0.955, 0.936},    {1, 1, 0, 0, 7, 1.0, 1.0, 0.809, 0.841},
        {1, 1, 2, 0, 7, 1.0, 1.0, 0.939, 0.926},       {2, 1, 2, 0, 7, 1.0, 1.0, 0.916, 0.944},
        {2, 1, 2, 3, 7, 1.0, 1.0, 0.916, 0.944},       {2, 2, 2, 3, 7, 1.0, 1.0, 0.873, 0.900}};
    // The scene and the query are deterministic: object counts exact, precision and recall to
    // the table's three decimals; pooled IoU moves by a few thousandths when a handful of voxels
    // change, so it is held to 0.02 (under a third of the smallest shortfall, 0.045).
    constexpr double kRatioTolerance = 0.0005;
    constexpr double kIoUTolerance = 0.02;
    std::vector<ChangeScore> scores;
    for (const Row& row : rows) {
        ChangeQuery q;
        q.surface_tolerance_voxels = row.tolerance;
        q.observed_margin_voxels = row.margin;
        q.grow_voxels = row.grow;
        q.support_depth_voxels = row.support;
        const ChangeScore mapped = testing::ScoreChanges(s, q, false, false);
        const ChangeScore strict = testing::ScoreChanges(s, q, true, false);
        std::printf("[ change ] | %d | %d | %d | %d | %zu | %.3f | %.3f | %.3f | %.3f |\n",
                    row.tolerance, row.margin, row.grow, row.support, mapped.objects,
                    mapped.precision, mapped.recall, mapped.iou, strict.iou);
        SCOPED_TRACE(std::to_string(row.tolerance) + std::to_string(row.margin) +
                     std::to_string(row.grow) + std::to_string(row.support));
        EXPECT_EQ(mapped.objects, row.objects);
        EXPECT_NEAR(mapped.precision, row.precision, kRatioTolerance);
        EXPECT_NEAR(mapped.recall, row.recall, kRatioTolerance);
        EXPECT_NEAR(mapped.iou, row.iou, kIoUTolerance);
        EXPECT_NEAR(strict.iou, row.strict_iou, kIoUTolerance);
        scores.push_back(mapped);
    }
    EXPECT_GT(scores[4].iou, scores[3].iou) << "growth gives back voxels the safeguards trimmed";
    EXPECT_EQ(scores[6].iou, scores[5].iou) << "the support rule changes nothing here";
    EXPECT_LT(scores[7].iou, scores[6].iou) << "a margin of 2 costs the wall cut voxels";
}

// Every reported voxel was observed (occupied or free) by both sessions: where one side never
// looked, nothing is reported, growth included.
TEST(ChangeSimulated, NothingIsReportedWhereOneSessionNeverLooked) {
    const ChangeCase& s = Scene();
    const ChangeSet changes = DetectChanges(s.a, s.b, kVoxel, ChangeQuery{});
    const auto seen = [](const Observation& o) {
        BoolGrid::Ptr all = o.masks.occupied->deepCopy();
        all->topologyUnion(*o.masks.free);
        return all;
    };
    BoolGrid::Ptr both = seen(s.a);
    both->topologyIntersection(*seen(s.b));
    size_t reported = 0, unseen = 0;
    for (const BoolGrid* grid : {changes.added.get(), changes.removed.get()}) {
        for (auto on = grid->cbeginValueOn(); on; ++on) {
            ++reported;
            unseen += both->tree().isValueOn(on.getCoord()) ? 0 : 1;
        }
    }
    std::printf("[ change ] %zu voxels reported, %zu of them unseen by a side\n", reported, unseen);
    // The seven edits: 3,614 voxels measured (docs/change.md); a few voxels either way when the
    // change rules are retuned, not a factor.
    EXPECT_NEAR(static_cast<double>(reported), 3614.0, 0.01 * 3614.0);
    EXPECT_EQ(unseen, 0u);
}

}  // namespace
}  // namespace strata::change::simulated_tests
