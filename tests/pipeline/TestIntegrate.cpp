// IntegrateSession: a session into a map created on first use; with --align the session is
// aligned first and a refusal commits nothing; a failure leaves no new map behind.
#include <gtest/gtest.h>

#include "PipelineTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/Integrate.hpp"
#include "strata/registration/Register.hpp"

namespace strata::pipeline::test {
namespace {

TEST(PipelineIntegrate, CreatesTheMapThenAddsASessionReportingProgress) {
    const fs::path dir = Temp("integrate");
    std::vector<ProgressEvent> events;
    int starts = 0;
    IntegrateOptions options;
    options.progress = [&](const ProgressEvent& e) { events.push_back(e); };
    options.on_start = [&](const IntegrationStart& s) {
        ++starts;
        EXPECT_TRUE(s.created);
        EXPECT_EQ(s.source.size(), 3u);
    };
    const IntegrateResult first = IntegrateRoom(dir, "first", {}, options);
    EXPECT_TRUE(first.created);
    EXPECT_EQ(starts, 1);
    EXPECT_EQ(first.session.name, "first");
    EXPECT_EQ(first.session.scans, 3u);
    EXPECT_EQ(first.session.points, 3u * 4000u);
    EXPECT_GT(first.map_tiles, 0u);
    ASSERT_EQ(events.size(), 4u);  // 0, 1, 2, 3 of 3
    for (size_t i = 0; i < events.size(); ++i) {
        EXPECT_EQ(events[i].stage, "integrating");
        EXPECT_EQ(events[i].done, i);
        EXPECT_EQ(events[i].total, 3u);
    }
    const IntegrateResult second = IntegrateRoom(dir, "second");
    EXPECT_FALSE(second.created);
    EXPECT_EQ(store::MapStore::Open(dir, store::MapStore::Access::kRead).Latest().sessions.size(),
              2u);
}

TEST(PipelineIntegrate, AlignsASessionRecordedInAMovedFrameAndKeepsTheTransform) {
    constexpr double kTranslationTolM = 0.03;
    constexpr double kYawTolDeg = 0.2;
    const fs::path dir = Temp("align");
    (void)IntegrateRoom(dir, "day1", StillRoom(Hall()));
    IntegrateOptions options;
    options.align = CloseRangeAlignment();
    std::vector<std::string> stages;
    options.progress = [&](const ProgressEvent& e) {
        if (stages.empty() || stages.back() != e.stage) stages.push_back(e.stage);
    };
    const IntegrateResult r = IntegrateRoom(dir, "day2", StillRoom(HallInAMovedFrame()), options);
    ASSERT_TRUE(r.alignment);
    const Eigen::Isometry3d truth = HallInAMovedFrame().T_session_world.inverse();
    const Eigen::Isometry3d T = r.alignment->result.T_map_source;
    EXPECT_LT((T.translation() - truth.translation()).norm(), kTranslationTolM);
    EXPECT_NEAR(registration::YawDeg(T), registration::YawDeg(truth), kYawTolDeg);
    EXPECT_TRUE(r.session.alignment.isApprox(T.matrix()));
    EXPECT_EQ(r.session.notes.rfind("alignment {", 0), 0u) << r.session.notes;
    EXPECT_EQ(stages, (std::vector<std::string>{"reading scans", "integrating"}));
}

TEST(PipelineIntegrate, ARefusedAlignmentCommitsNothing) {
    const fs::path dir = Temp("refused");
    (void)IntegrateRoom(dir, "day1", StillRoom(Hall()));
    const MapState before = StateOf(dir);
    IntegrateOptions options;
    options.align = CloseRangeAlignment();
    options.align->options.config.max_rmse_m = 1e-6;  // no real alignment is this good
    bool reported = false;
    options.on_aligned = [&](const MapAlignment& a) { reported = !a.result.converged; };
    options.on_start = [](const IntegrationStart&) { ADD_FAILURE() << "integration started"; };
    try {
        (void)IntegrateRoom(dir, "day2", StillRoom(HallInAMovedFrame()), options);
        ADD_FAILURE() << "the alignment was accepted";
    } catch (const RefusedError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("--align: the alignment of ", 0), 0u) << e.what();
    }
    EXPECT_TRUE(reported) << "on_aligned sees the refused alignment";
    // Far from the map: no surface near the guess, refused as well.
    options.align = CloseRangeAlignment();
    options.align->guess = registration::PoseFromXyzYaw(500.0, 500.0, 0.0, 0.0);
    EXPECT_THROW((void)IntegrateRoom(dir, "day2", Hall(), options), RefusedError);
    EXPECT_EQ(StateOf(dir), before);
}

TEST(PipelineIntegrate, AFailureLeavesNoNewMapAndAnExistingMapUntouched) {
    // --align needs a map to align to: refused before a map is created.
    const fs::path dir = Temp("failed");
    IntegrateOptions align;
    align.align = AlignRequest{};
    EXPECT_THROW((void)IntegrateRoom(dir, "first", {}, align), InvalidArgumentError);
    EXPECT_FALSE(fs::exists(dir));

    // A scan cut mid-record: the new map is removed again.
    ScanSpec scans;
    scans.kitti = MakeSequence(Temp("failed_seq"));
    fs::resize_file(scans.kitti / "velodyne" / "000002.bin", 16 * 100 + 7);
    EXPECT_THROW((void)IntegrateSession(dir, scans, {}), FormatError);
    EXPECT_FALSE(fs::exists(dir / "catalog.sqlite"));

    // An existing map: the same failure changes nothing, nor does a conflicting flag.
    (void)IntegrateRoom(dir, "first");
    const MapState before = StateOf(dir);
    EXPECT_THROW((void)IntegrateSession(dir, scans, {}), FormatError);
    IntegrateOptions conflicting;
    conflicting.map.rule.points_only = true;
    try {
        (void)IntegrateRoom(dir, "second", {}, conflicting);
        ADD_FAILURE() << "--points-only was accepted on a map that traces free space";
    } catch (const InvalidArgumentError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("--points-only: ", 0), 0u) << e.what();
    }
    EXPECT_EQ(StateOf(dir), before);
    IntegrateOptions budget;
    budget.memory_budget_mb = -1.0;
    EXPECT_THROW((void)IntegrateRoom(dir, "second", {}, budget), InvalidArgumentError);
}

}  // namespace
}  // namespace strata::pipeline::test
