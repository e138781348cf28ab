// A session shared by several writers, each keeping some tiles (what `mpirun` ranks do,
// docs/scale.md): the committed map must be the map one writer makes.
#include <gtest/gtest.h>

#include <set>

#include "StoreTestUtil.hpp"
#include "strata/core/Error.hpp"

namespace strata::store::test {
namespace {

// Two owners by tile column parity: neighbouring tiles always belong to different writers, so
// every update of the room crosses from one to the other many times.
bool EvenColumn(const TileKey& key) { return key.x % 2 == 0; }

std::set<std::string> FilesUnder(const fs::path& dir) {
    std::set<std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(dir / "tiles")) {
        if (e.is_regular_file()) out.insert(fs::relative(e.path(), dir).string());
    }
    return out;
}

void ExpectSameLayers(const MapStore& a, const MapStore& b) {
    const Snapshot sa = a.Latest(), sb = b.Latest();
    ASSERT_EQ(sa.layers.size(), sb.layers.size());
    for (size_t i = 0; i < sa.layers.size(); ++i) {
        EXPECT_EQ(sa.layers[i].key, sb.layers[i].key);
        EXPECT_EQ(testing::LayerDifference(a.ReadLayer(sa.layers[i]), b.ReadLayer(sb.layers[i])),
                  "");
    }
}

// Integrates `scans` as one session of `map` split between this process's writer (even tile
// columns) and a worker on a read-only store of the same map (odd columns). Each scan's update is
// computed once, by the writer whose turn it is, and applied by both, as ranks do.
SessionRecord SplitSession(MapStore& map, const std::vector<Scan>& scans) {
    MapStore read = MapStore::Open(map.dir(), MapStore::Access::kRead);
    SessionOptions own;
    own.owns = EvenColumn;
    SessionWriter committer(map, {}, own);
    SessionOptions other;
    other.owns = [](const TileKey& key) { return !EvenColumn(key); };
    other.worker_of_session = committer.session_id();
    SessionWriter worker(read, {}, other);
    for (size_t i = 0; i < scans.size(); ++i) {
        SessionWriter& computes = i % 2 == 0 ? committer : worker;
        const integration::ScanUpdate update = computes.Integrate(scans[i]);
        (i % 2 == 0 ? worker : committer).Apply(update);
        if (i % 2 == 1) committer.AddScan(SessionWriter::RecordOf(scans[i], update));
    }
    return committer.Commit({worker.WriteFiles()});
}

TEST(SessionWorkers, ASessionSplitBetweenWritersIsTheSessionOneWriterMakes) {
    const std::vector<Scan> first = Session(1, {0.4, 0.2, 0.0}, 4);
    const std::vector<Scan> second = Session(11, {2.1, -0.8, 0.2}, 3);
    MapStore one = NewMap(Temp("workers_one"));
    MapStore split = NewMap(Temp("workers_split"));
    (void)Write(one, first);
    (void)Write(one, second);
    (void)SplitSession(split, first);
    const SessionRecord s2 = SplitSession(split, second);
    EXPECT_EQ(s2.id, 2);
    EXPECT_EQ(s2.scans, second.size());
    EXPECT_EQ(s2.points, one.Latest().sessions.back().points);
    ExpectSameMap(split.LoadMap(split.Latest()), one.LoadMap(one.Latest()));
    ExpectSameMap(split.LoadMap(split.AsOf(1)), one.LoadMap(one.AsOf(1)));
    ExpectSameLayers(split, one);
    EXPECT_EQ(split.Latest().tiles.size(), one.Latest().tiles.size());
    // Both writers wrote some of the tiles.
    std::set<bool> parities;
    for (const TileVersion& v : split.Latest().tiles) parities.insert(EvenColumn(v.key));
    EXPECT_EQ(parities.size(), 2u);
    const std::vector<ScanRecord> scans = split.Scans(2);
    ASSERT_EQ(scans.size(), second.size());
    for (size_t i = 0; i < scans.size(); ++i) {
        EXPECT_EQ(scans[i].index, i);
        EXPECT_EQ(scans[i].source, second[i].source);
    }
    EXPECT_TRUE(split.Check().ok());
}

TEST(SessionWorkers, AWorkerNeedsACommitterAndCannotCommit) {
    const fs::path dir = Temp("workers_alone");
    { (void)NewMap(dir); }  // created, then the lock released
    MapStore read = MapStore::Open(dir, MapStore::Access::kRead);
    SessionOptions options;
    options.worker_of_session = 1;
    EXPECT_TRUE(ThrowsNaming<InvalidArgumentError>([&] { SessionWriter w(read, {}, options); },
                                                   "writer lock"));
    MapStore map = MapStore::Open(dir, MapStore::Access::kWrite);
    SessionWriter worker(read, {}, options);
    (void)worker.Integrate(RoomScan(3, {0, 0, 0}));
    EXPECT_TRUE(ThrowsNaming<InvalidArgumentError>([&] { (void)worker.Commit(); }, "WriteFiles"));
}

TEST(SessionWorkers, TwoWritersOfOneTileAreRefusedAndLeaveNoFile) {
    const fs::path dir = Temp("workers_overlap");
    MapStore map = NewMap(dir);
    (void)Write(map, Session(1, {0, 0, 0}, 2));
    const std::set<std::string> before = FilesUnder(dir);
    const int64_t commit = map.Latest().commit;
    MapStore read = MapStore::Open(dir, MapStore::Access::kRead);
    {
        SessionWriter committer(map, {}, {});  // keeps every tile
        SessionOptions other;
        other.worker_of_session = committer.session_id();  // and so does this one
        SessionWriter worker(read, {}, other);
        const Scan scan = RoomScan(7, {0.5, 0, 0});
        worker.Apply(committer.Integrate(scan));
        const SessionFiles files = worker.WriteFiles();
        EXPECT_FALSE(files.versions.empty());
        EXPECT_TRUE(ThrowsNaming<InvalidArgumentError>([&] { (void)committer.Commit({files}); },
                                                       "two writers"));
    }
    EXPECT_EQ(map.Latest().commit, commit);
    EXPECT_EQ(FilesUnder(dir), before);
    EXPECT_TRUE(map.Check().ok());
}

}  // namespace
}  // namespace strata::store::test
