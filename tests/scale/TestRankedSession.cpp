// A session integrated by every rank equals the session one process integrates: same fused
// grids, same layers, same catalog rows (docs/scale.md, "Integrate").
#include <gtest/gtest.h>

#include <set>

#include "MpiTest.hpp"
#include "StoreTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/RankedSession.hpp"

namespace strata::pipeline {
namespace {

using store::test::ExpectSameMap;
using test::TestRanks;
namespace fs = std::filesystem;

// A path every rank shares: rank 0's scratch path (each rank's own would carry its pid).
fs::path SharedTemp(const std::string& name) {
    const Ranks& ranks = TestRanks();
    const std::string mine = ranks.root() ? store::test::Temp(name).string() : "";
    return ranks.Broadcast(mine);
}

store::MapStore OpenShared(const fs::path& dir) {
    return OpenOnRanks(dir, TestRanks(), [&] {
        return store::MapStore::IsMap(dir)
                   ? store::MapStore::Open(dir, store::MapStore::Access::kWrite)
                   : store::test::NewMapOfManyTiles(dir);
    });
}

// Blocks of two scans: the sessions of 4-5 scans here give every rank of 2 some scans to cast,
// and rounds that end in a partial block.
constexpr size_t kTestScansPerBlock = 2;

RankedSessionResult Integrate(store::MapStore& map, const std::vector<core::Scan>& scans,
                              const std::string& name) {
    return IntegrateOnRanks(
        map, scans.size(), [&](size_t i) { return scans[i]; }, {}, store::test::Named(name),
        TestRanks(), {}, kTestScansPerBlock);
}

void ExpectSameLayers(const store::MapStore& a, const store::MapStore& b) {
    const store::Snapshot sa = a.Latest(), sb = b.Latest();
    ASSERT_EQ(sa.layers.size(), sb.layers.size());
    for (size_t i = 0; i < sa.layers.size(); ++i) {
        EXPECT_EQ(sa.layers[i].key, sb.layers[i].key);
        EXPECT_EQ(testing::LayerDifference(a.ReadLayer(sa.layers[i]), b.ReadLayer(sb.layers[i])),
                  "");
    }
}

TEST(RankedSession, EveryRankCountGivesTheMapOneProcessGives) {
    const std::vector<core::Scan> first = store::test::Session(1, {0.4, 0.2, 0.0}, 5);
    const std::vector<core::Scan> second = store::test::Session(21, {2.6, -1.3, 0.2}, 4);
    const fs::path dir = SharedTemp("ranked_map");
    {
        store::MapStore map = OpenShared(dir);
        const RankedSessionResult one = Integrate(map, first, "first");
        EXPECT_EQ(one.session.id, 1);
    }
    store::MapStore map = OpenShared(dir);  // the next command: opened again
    const RankedSessionResult two = Integrate(map, second, "second");
    EXPECT_EQ(two.session.id, 2);
    EXPECT_EQ(two.session.name, "second");
    EXPECT_EQ(two.session.scans, second.size());
    EXPECT_GT(two.stats.tiles_written, 10u);
    if (!TestRanks().root()) return;
    // The reference: one process, one writer.
    store::MapStore reference =
        store::test::NewMapOfManyTiles(store::test::Temp("ranked_reference"));
    (void)store::test::Write(reference, first, store::test::Named("first"));
    (void)store::test::Write(reference, second, store::test::Named("second"));
    ExpectSameMap(map.LoadMap(map.Latest()), reference.LoadMap(reference.Latest()));
    ExpectSameMap(map.LoadMap(map.AsOf(1)), reference.LoadMap(reference.AsOf(1)));
    ExpectSameLayers(map, reference);
    // Summed over ranks, the session wrote one fused version per tile it touched.
    size_t touched = 0;
    for (const store::TileVersion& v : reference.Latest().tiles) {
        touched += v.commit == reference.Latest().sessions.back().commit ? 1 : 0;
    }
    EXPECT_EQ(two.stats.tiles_written, touched);
    const auto scans = map.Scans(2), expected = reference.Scans(2);
    ASSERT_EQ(scans.size(), expected.size());
    for (size_t i = 0; i < scans.size(); ++i) {
        EXPECT_EQ(scans[i].index, expected[i].index);
        EXPECT_EQ(scans[i].source, expected[i].source);
        EXPECT_EQ(scans[i].points, expected[i].points);
        EXPECT_TRUE(scans[i].pose.isApprox(expected[i].pose, 0.0));
    }
    EXPECT_EQ(map.Latest().sessions.back().points, reference.Latest().sessions.back().points);
    // With several ranks, every rank kept some of the tiles.
    std::set<int> owners;
    for (const store::TileVersion& v : map.Latest().tiles) {
        owners.insert(TileOwner(v.key, TestRanks().size()));
    }
    EXPECT_EQ(owners.size(), static_cast<size_t>(TestRanks().size()));
    EXPECT_TRUE(map.Check().ok());
}

TEST(RankedSession, AFailingRankFailsEveryRankAndCommitsNothing) {
    const std::vector<core::Scan> scans = store::test::Session(41, {0.4, 0.2, 0.0}, 5);
    const fs::path dir = SharedTemp("ranked_failure");
    store::MapStore map = OpenShared(dir);
    (void)Integrate(map, scans, "kept");
    const int64_t commit = map.Latest().commit;
    // The last rank cannot read the last of its scans.
    const Ranks& ranks = TestRanks();
    const auto n = static_cast<size_t>(ranks.size());
    // Rank r reads the r-th block of each round of n blocks (n <= 3 here: rank n - 1 has one).
    const auto reader_of = [&](size_t i) {
        return (i % (kTestScansPerBlock * n)) / kTestScansPerBlock;
    };
    size_t failing = scans.size() - 1;
    while (reader_of(failing) != n - 1) --failing;
    const int failing_rank = static_cast<int>(n - 1);
    try {
        (void)IntegrateOnRanks(
            map, scans.size(),
            [&](size_t i) {
                if (i == failing)
                    throw FormatError("scan_" + std::to_string(i) + ".pcd: bad header");
                return scans[i];
            },
            {}, store::test::Named("lost"), ranks, {}, kTestScansPerBlock);
        ADD_FAILURE() << "no rank threw";
    } catch (const FormatError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("bad header"), std::string::npos) << what;
        if (ranks.rank() != failing_rank) {
            EXPECT_NE(what.find("rank " + std::to_string(failing_rank) + ":"), std::string::npos)
                << what;
        }
    }
    if (!ranks.root()) return;
    const store::MapStore after = store::MapStore::Open(dir, store::MapStore::Access::kRead);
    EXPECT_EQ(after.Latest().commit, commit);
    EXPECT_EQ(after.Latest().sessions.size(), 1u);
    EXPECT_TRUE(after.Check().ok());
}

TEST(RankedSession, TileOwnersSpreadNeighbouringTiles) {
    for (int n : {2, 3, 4}) {
        std::vector<int> counts(static_cast<size_t>(n), 0);
        for (int x = -8; x < 8; ++x) {
            for (int y = -8; y < 8; ++y) ++counts[static_cast<size_t>(TileOwner({x, y}, n))];
        }
        for (int c : counts) EXPECT_NEAR(c, 256.0 / n, 256.0 / n * 0.25) << n;
        // Along a row and along a column, any n tiles in a row are n ranks.
        for (int k = -8; k + n <= 8; ++k) {
            std::set<int> row, column;
            for (int j = 0; j < n; ++j) {
                row.insert(TileOwner({k + j, 3}, n));
                column.insert(TileOwner({-5, k + j}, n));
            }
            EXPECT_EQ(row.size(), static_cast<size_t>(n));
            EXPECT_EQ(column.size(), static_cast<size_t>(n));
        }
    }
    EXPECT_EQ(TileOwner({5, -7}, 1), 0);
}

}  // namespace
}  // namespace strata::pipeline
