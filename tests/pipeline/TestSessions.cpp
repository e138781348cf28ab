// The sessions of a map: listed with their history, one removed (still readable as of before).
#include <gtest/gtest.h>

#include "PipelineTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/Sessions.hpp"

namespace strata::pipeline::test {
namespace {

TEST(PipelineSessions, ListsEverySessionAndMarksTheRemovedOne) {
    const fs::path dir = Temp("sessions");
    (void)IntegrateRoom(dir, "monday");
    (void)IntegrateRoom(dir, "tuesday");
    store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kWrite);
    const RemovedSession removed = RemoveSession(map, "monday");
    EXPECT_EQ(removed.id, 1);
    EXPECT_GT(removed.commit, 0);
    EXPECT_EQ(map.Latest().sessions.size(), 1u);

    const nlohmann::json list = SessionHistoryJson(map);
    ASSERT_EQ(list.size(), 2u);
    EXPECT_EQ(list[0].at("name"), "monday");
    EXPECT_EQ(list[0].at("removed_commit"), removed.commit);
    EXPECT_EQ(list[1].at("name"), "tuesday");
    EXPECT_EQ(list[1].at("removed_commit"), 0);
    EXPECT_EQ(list[1].at("scans"), 3);
    for (const char* key : {"id", "source", "points", "start_utc", "end_utc", "commit"}) {
        EXPECT_TRUE(list[1].contains(key)) << key;
    }
}

TEST(PipelineSessions, RemovingAnUnknownSessionOrFromAReaderIsRefused) {
    const fs::path dir = Temp("sessions_refused");
    (void)IntegrateRoom(dir, "only");
    const MapState before = StateOf(dir);
    {
        store::MapStore writer = store::MapStore::Open(dir, store::MapStore::Access::kWrite);
        EXPECT_THROW((void)RemoveSession(writer, "no_such_session"), NotFoundError);
    }
    store::MapStore reader = store::MapStore::Open(dir, store::MapStore::Access::kRead);
    EXPECT_THROW((void)RemoveSession(reader, "only"), InvalidArgumentError);
    EXPECT_EQ(StateOf(dir), before);
}

}  // namespace
}  // namespace strata::pipeline::test
