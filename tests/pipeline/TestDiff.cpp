// Diff's use cases beyond two stored sides: scans not yet integrated as a side, and change sets
// kept in the catalog and listed.
#include <gtest/gtest.h>

#include "PipelineTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/Diff.hpp"

namespace strata::pipeline::test {
namespace {

TEST(PipelineDiff, NewScansAreASideAndAComparisonIsSavedAndListed) {
    const fs::path dir = Temp("diff");
    (void)IntegrateRoom(dir, "day1", StillRoom(Hall()));
    const MapState before = StateOf(dir, "change_sets");
    store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kWrite);
    ScanSpec scans;
    scans.kitti = MakeSequence(Temp("diff_seq"), StillRoom(Hall()));
    change::MapObserver observer(map, {});
    const DiffSide a = ResolveSide("map", map, observer);
    const DiffSide b = ObserveScans(map, scans);
    EXPECT_EQ(b.name, "scans " + scans.kitti.string() + " (3, uncommitted)");
    EXPECT_EQ(StateOf(dir, "change_sets"), before) << "observing scans writes nothing";

    // The same room scanned again: nothing added or removed.
    const DiffResult same = CompareSides(a, b, map, change::ChangeQuery{});
    EXPECT_TRUE(same.changes.objects.empty());
    EXPECT_EQ(same.changes.added_voxels_total, 0u);
    EXPECT_EQ(same.changes.removed_voxels_total, 0u);

    const int64_t id = SaveChangeSet(map, a, b, same);
    const nlohmann::json sets = ChangeSetsJson(map);
    ASSERT_EQ(sets.size(), 1u);
    EXPECT_EQ(sets[0].at("id"), id);
    EXPECT_EQ(sets[0].at("from"), a.name);
    EXPECT_EQ(sets[0].at("to"), b.name);
    EXPECT_EQ(sets[0].at("objects"), 0);
    EXPECT_TRUE(sets[0].at("report").is_object());
}

TEST(PipelineDiff, SavingFromAReaderIsRefused) {
    const fs::path dir = Temp("diff_reader");
    (void)IntegrateRoom(dir, "day1");
    store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kRead);
    change::MapObserver observer(map, {});
    const DiffSide a = ResolveSide("map", map, observer);
    const DiffResult diff = CompareSides(a, a, map, change::ChangeQuery{});
    EXPECT_THROW((void)SaveChangeSet(map, a, a, diff), InvalidArgumentError);
    EXPECT_TRUE(ChangeSetsJson(map).empty());
}

}  // namespace
}  // namespace strata::pipeline::test
