// RegisterScans: where a session recorded in a moved frame sits in the map, the map only read;
// ReadSourceCloud keeps one scan in its own frame and accumulates a session in its poses' frame.
#include <gtest/gtest.h>

#include "PipelineTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/Register.hpp"

namespace strata::pipeline::test {
namespace {

TEST(PipelineRegister, ReadSourceCloudKeepsOneScanAsItIsAndAccumulatesASession) {
    const fs::path seq = MakeSequence(Temp("cloud_seq"), Hall());
    const ScanSource one = ScanSource::Kitti(seq, "1");
    const SourceCloud single = ReadSourceCloud(one, true, AlignOptions{});
    EXPECT_TRUE(single.single_scan);
    EXPECT_EQ(single.points.size(), static_cast<size_t>(Hall().points_per_scan));
    constexpr double kFloat32M = 1e-5;  // .bin files hold float32
    EXPECT_LT((single.points[7] - RoomScans(Hall())[1].points[7]).norm(), kFloat32M)
        << "the sensor frame, unfiltered";

    const ScanSource all = ScanSource::Kitti(seq, "");
    size_t events = 0;
    const SourceCloud session =
        ReadSourceCloud(all, true, AlignOptions{}, [&](const ProgressEvent& e) {
            EXPECT_EQ(e.stage, "reading scans");
            ++events;
        });
    EXPECT_FALSE(session.single_scan);
    EXPECT_EQ(session.scans, 3u);
    EXPECT_EQ(events, 4u);
    EXPECT_GT(session.points.size(), 0u);
    EXPECT_LT(session.points.size(), 3u * Hall().points_per_scan) << "thinned, near points out";
    EXPECT_THROW((void)ReadSourceCloud(ScanSource::Files({}, "", {}), true, AlignOptions{}),
                 InvalidArgumentError);
}

TEST(PipelineRegister, FindsASessionRecordedInAMovedFrameAndLeavesTheMap) {
    constexpr double kTranslationTolM = 0.03;
    const fs::path dir = Temp("register");
    (void)IntegrateRoom(dir, "day1", StillRoom(Hall()));
    const MapState before = StateOf(dir);
    const store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kRead);
    RegisterOptions options;
    options.scans.kitti = MakeSequence(Temp("register_seq"), StillRoom(HallInAMovedFrame()));
    options.align = CloseRangeAlignment();
    const Registration r = RegisterScans(map, options);
    ASSERT_TRUE(r.alignment.result.converged) << r.alignment.result.refusal;
    EXPECT_FALSE(r.single_scan);
    EXPECT_EQ(r.scans, 3u);
    const Eigen::Isometry3d truth = HallInAMovedFrame().T_session_world.inverse();
    EXPECT_LT((r.alignment.result.T_map_source.translation() - truth.translation()).norm(),
              kTranslationTolM);
    const nlohmann::json j = RegistrationJson(r);
    EXPECT_EQ(j.at("source"), options.scans.kitti.string());
    EXPECT_EQ(j.at("scans"), 3);
    EXPECT_EQ(j.at("T").size(), 16u);
    EXPECT_TRUE(j.at("converged").get<bool>());

    options.as_of = "no_such_session";
    EXPECT_THROW((void)RegisterScans(map, options), NotFoundError);
    EXPECT_EQ(StateOf(dir), before);
}

}  // namespace
}  // namespace strata::pipeline::test
