// The store: commits, snapshots, session layers, eviction, removal, locking and damaged files,
// on synthetic scans whose in-memory integration is the known answer.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <set>
#include <thread>

#include "StoreTestUtil.hpp"
#include "strata/core/Error.hpp"

namespace strata::store::test {
namespace {

TEST(Store, CreateRecordsSettingsAndRefusesToOverwrite) {
    const fs::path dir = Temp("create");
    StoreSettings settings;
    settings.voxel_size_m = 0.15;
    settings.tile_size_m = 64.0;
    settings.origin = Eigen::Vector3d(500000.0, 4000000.0, 30.0);
    { (void)MapStore::Create(dir, settings); }
    const MapStore map = MapStore::Open(dir, MapStore::Access::kRead);
    EXPECT_DOUBLE_EQ(map.settings().voxel_size_m, 0.15);
    // 64 m / 0.15 m = 426.7 voxels, rounded to whole 8-voxel leaves: 53 leaves.
    EXPECT_EQ(map.settings().tile_voxels, 424);
    EXPECT_EQ(map.settings().origin, settings.origin);
    EXPECT_EQ(map.settings().format_version, MapStore::kFormatVersion);
    EXPECT_EQ(map.Latest().sessions.size(), 0u);
    EXPECT_EQ(map.settings().integration.max_range_m, IntegrationConfig{}.max_range_m);
    EXPECT_TRUE(ThrowsNaming<InvalidArgumentError>([&] { (void)MapStore::Create(dir, settings); },
                                                   dir.string()));
    EXPECT_TRUE(ThrowsNaming<NotFoundError>(
        [&] { (void)MapStore::Open(Temp("nothing"), MapStore::Access::kRead); },
        "no such map directory"));
    const fs::path empty = Temp("empty");
    fs::create_directories(empty);
    EXPECT_TRUE(ThrowsNaming([&] { (void)MapStore::Open(empty, MapStore::Access::kRead); },
                             "not a strata map"));
}

TEST(Store, TileKeysFloorNegativeCoordinates) {
    MapSettings s;
    s.tile_voxels = 32;
    EXPECT_EQ(s.TileOf({0, 31, 5}), (TileKey{0, 0}));
    EXPECT_EQ(s.TileOf({-1, 32, 5}), (TileKey{-1, 1}));
    EXPECT_EQ(s.TileOf({-32, -33, 5}), (TileKey{-1, -2}));
    EXPECT_TRUE(s.TileBounds({-1, 1}).isInside(openvdb::Coord(-1, 32, -100000)));
}

TEST(Store, SessionsEqualInMemoryIntegrationAndSnapshotsGoBack) {
    const fs::path dir = Temp("sessions");
    const auto first = Session(1, {0, 0, 0});
    const auto second = Session(10, {4.0, 1.0, 0.0});
    {
        MapStore map = NewMapOfManyTiles(dir);
        const auto s1 = Write(map, first, Named("first"));
        const auto s2 = Write(map, second, Named("second"));
        EXPECT_EQ(s1.id, 1);
        EXPECT_EQ(s2.id, 2);
        EXPECT_EQ(s2.scans, 3u);
    }
    const MapStore map = MapStore::Open(dir, MapStore::Access::kRead);
    const auto latest = map.Latest();
    ASSERT_EQ(latest.sessions.size(), 2u);
    EXPECT_EQ(latest.sessions[1].name, "second");
    EXPECT_GT(latest.tiles.size(), 8u);  // the rooms span many 3.2 m tiles
    {
        SCOPED_TRACE("latest");
        ExpectSameMap(map.LoadMap(latest), InMemory({first, second}));
    }
    {
        SCOPED_TRACE("as of session 1");
        ExpectSameMap(map.LoadMap(map.AsOf(1)), InMemory({first}));
    }
    EXPECT_EQ(map.AsOf(1).sessions.size(), 1u);
    EXPECT_EQ(map.FindSession("second"), 2);
    EXPECT_EQ(map.FindSession("1"), 1);
    EXPECT_TRUE(
        ThrowsNaming<NotFoundError>([&] { (void)map.FindSession("nope"); }, "no session 'nope'"));
    const auto scans = map.Scans(2);
    ASSERT_EQ(scans.size(), 3u);
    EXPECT_EQ(scans[1].source, "room_11");
    EXPECT_TRUE(scans[2].pose.isApprox(second[2].T_world_sensor, 1e-12));
    EXPECT_TRUE(map.Check().ok());
}

TEST(Store, UntouchedTilesAreNotRewritten) {
    const fs::path dir = Temp("untouched");
    MapStore map = NewMap(dir);
    (void)Write(map, Session(1, {0, 0, 0}));
    const auto before = map.Latest();
    // A small scan far inside one tile: only the tiles its rays cross get new versions.
    Scan small;
    small.T_world_sensor.translation() = Eigen::Vector3d(1.65, 1.65, 0.05);
    small.points = {{0.5, 0.0, 0.0}, {0.0, 0.5, 0.0}};
    (void)Write(map, {small});
    const auto after = map.Latest();
    ASSERT_EQ(after.tiles.size(), before.tiles.size());
    size_t rewritten = 0;
    for (size_t i = 0; i < after.tiles.size(); ++i) {
        if (after.tiles[i].version != before.tiles[i].version) {
            ++rewritten;
            EXPECT_EQ(after.tiles[i].key, (TileKey{0, 0}));
        } else {
            EXPECT_EQ(after.tiles[i].file, before.tiles[i].file);
        }
    }
    EXPECT_EQ(rewritten, 1u);
    // The commit wrote that tile's next fused version and the new session's layers there:
    // nothing else, and no earlier session's layers.
    const auto layers = map.SessionLayers(2);
    ASSERT_EQ(layers.size(), 1u);
    EXPECT_EQ(layers[0].key, (TileKey{0, 0}));
    EXPECT_EQ(layers[0].file, "tiles/0_0/s2.vdb");
    EXPECT_EQ(map.SessionLayers(1).size(), before.tiles.size());
}

// The cost of a commit follows the session, not the map's age: the same scans committed again
// and again write the same bytes each time, and the map on disk grows by that much per session.
TEST(Store, CommitsWriteTheSameBytesWhateverTheMapsAge) {
    const fs::path dir = Temp("flat");
    MapStore map = NewMap(dir);
    const auto scans = Session(1, {0, 0, 0}, 2);
    std::vector<uint64_t> written;
    for (int s = 0; s < 8; ++s) {
        SessionWriter writer(map, IntegrationConfig{}, {});
        for (const Scan& scan : scans) (void)writer.Integrate(scan);
        (void)writer.Commit();
        written.push_back(writer.stats().bytes_written);
        EXPECT_EQ(writer.stats().layers_written, writer.stats().tiles_written);
    }
    // Session 2 onwards re-observes the same voxels: fused files keep their size, and every
    // session's layers are the same: equal to the byte (docs/store.md).
    EXPECT_EQ(written.back(), written[1]);
    const StorageBytes bytes = map.Bytes(map.Latest());
    EXPECT_EQ(bytes.layers, SumBytes(map.Latest().layers));
    EXPECT_GT(bytes.fused_older, 6 * bytes.fused_current);  // seven superseded versions per tile
    EXPECT_EQ(bytes.products, 0u);
}

TEST(Store, SessionLayersSayWhatEachSessionSaw) {
    const fs::path dir = Temp("layers");
    MapStore map = NewMap(dir);
    const auto first = Session(1, {0, 0, 0});
    (void)Write(map, first);
    (void)Write(map, Session(10, {4.0, 1.0, 0.0}));
    const VoxelMap only_first = InMemory({first});
    const Snapshot latest = map.Latest();
    ASSERT_GT(latest.layers.size(), latest.tiles.size());  // both sessions saw most tiles
    size_t occupied = 0;
    for (const LayerFile& file : latest.layers) {
        EXPECT_EQ(file.file, "tiles/" + std::to_string(file.key.x) + "_" +
                                 std::to_string(file.key.y) + "/s" + std::to_string(file.session) +
                                 ".vdb");
        const SessionLayer layer = map.ReadLayer(file);
        const auto version = std::find_if(latest.tiles.begin(), latest.tiles.end(),
                                          [&](const TileVersion& v) { return v.key == file.key; });
        ASSERT_NE(version, latest.tiles.end());
        const VoxelMap fused = map.ReadFused(*version);
        EXPECT_EQ(layer.occupied->getName(),
                  "session_" + std::to_string(layer.session) + "_occupied");
        // Disjoint, and inside what the fused map observed.
        auto free = layer.free->getConstAccessor();
        auto observed = fused.occupancy->getConstAccessor();
        EXPECT_EQ(layer.occupied->tree().activeTileCount(), 0u);
        for (auto it = layer.occupied->cbeginValueOn(); it; ++it) {
            EXPECT_TRUE(*it);
            EXPECT_FALSE(free.isValueOn(it.getCoord()));
            EXPECT_TRUE(observed.isValueOn(it.getCoord()));
        }
        // Session 1's layers are its own integration, thresholded.
        if (file.session != 1) continue;
        auto ref = only_first.occupancy->getConstAccessor();
        for (auto it = layer.occupied->cbeginValueOn(); it; ++it) {
            EXPECT_GT(ref.getValue(it.getCoord()), 0.0f);
            ++occupied;
        }
        for (auto it = layer.free->cbeginValueOn(); it; ++it) {
            EXPECT_TRUE(ref.isValueOn(it.getCoord()));
            EXPECT_LE(ref.getValue(it.getCoord()), 0.0f);
        }
    }
    size_t expected = 0;
    for (auto it = only_first.occupancy->cbeginValueOn(); it; ++it) expected += *it > 0.0f;
    EXPECT_EQ(occupied, expected);
}

TEST(Store, MemoryBudgetEvictsTilesAndGivesTheSameMap) {
    // Rooms 15 m apart (each 12 m wide): the session walks away from its first tiles and comes
    // back, so tiles are evicted, read back from their pending versions and written again.
    std::vector<Scan> walk;
    for (const double x : {0.0, 15.0, 30.0, 15.0, 0.0}) {
        walk.push_back(RoomScan(static_cast<uint32_t>(walk.size() + 40), {x, 0.2, 0.1}));
    }
    const auto first = Session(1, {0, 0, 0});
    const fs::path dir = Temp("budget");
    MapStore map = NewMap(dir);
    (void)Write(map, first);
    SessionOptions tight;
    tight.memory_budget_bytes = 2'000'000;  // about one room's tiles
    SessionWriter writer(map, IntegrationConfig{}, tight);
    for (const Scan& scan : walk) (void)writer.Integrate(scan);
    EXPECT_GT(writer.stats().tiles_evicted, 10u);
    EXPECT_GT(writer.stats().tiles_loaded, writer.stats().tiles_evicted / 2);
    (void)writer.Commit();
    ExpectSameMap(map.LoadMap(map.Latest()), InMemory({first, walk}));
    // Evictions wrote pending files that the commit kept or superseded: nothing is left over.
    const auto report = map.Check();
    EXPECT_TRUE(report.ok());
    EXPECT_TRUE(report.unreferenced.empty()) << report.unreferenced.front();
}

TEST(Store, RemovingASessionRebuildsOnlyWhatItSaw) {
    const fs::path dir = Temp("remove");
    MapStore map = NewMap(dir);
    const auto first = Session(1, {0, 0, 0});
    const auto second = Session(10, {9.0, 0.0, 0.0});  // a room further along: partly new space
    (void)Write(map, first);
    (void)Write(map, second);
    const VoxelMap before = map.LoadMap(map.Latest());
    (void)map.RemoveSession(2);
    const auto latest = map.Latest();
    ASSERT_EQ(latest.sessions.size(), 1u);
    const VoxelMap after = map.LoadMap(latest);
    const VoxelMap only_first = InMemory({first});
    const VoxelMap only_second = InMemory({second});
    auto first_acc = only_first.occupancy->getConstAccessor();
    auto second_acc = only_second.occupancy->getConstAccessor();
    auto after_acc = after.occupancy->getConstAccessor();
    // Every grid of a voxel: occupancy, label, label weight, endpoint (hits and point mean).
    const auto same_voxel = [&](const openvdb::Coord& ijk) {
        return after_acc.getValue(ijk) == before.occupancy->tree().getValue(ijk) &&
               after.label->tree().isValueOn(ijk) == before.label->tree().isValueOn(ijk) &&
               after.label->tree().getValue(ijk) == before.label->tree().getValue(ijk) &&
               after.label_weight->tree().getValue(ijk) ==
                   before.label_weight->tree().getValue(ijk) &&
               after.endpoints->tree().isValueOn(ijk) == before.endpoints->tree().isValueOn(ijk) &&
               after.endpoints->tree().getValue(ijk) == before.endpoints->tree().getValue(ijk);
    };
    const auto nothing_but_occupancy = [&](const openvdb::Coord& ijk) {
        return !after.label->tree().isValueOn(ijk) && !after.label_weight->tree().isValueOn(ijk) &&
               !after.endpoints->tree().isValueOn(ijk);
    };
    size_t kept = 0, forgotten = 0, both_occupied = 0, both_free = 0;
    for (auto it = before.occupancy->cbeginValueOn(); it; ++it) {
        const openvdb::Coord ijk = it.getCoord();
        const bool seen1 = first_acc.isValueOn(ijk), seen2 = second_acc.isValueOn(ijk);
        if (!seen2) {  // untouched by the removed session: bit-identical in every grid
            EXPECT_TRUE(same_voxel(ijk)) << ijk;
            ++kept;
        } else if (!seen1) {  // only the removed session saw it: unknown again, in every grid
            EXPECT_FALSE(after_acc.isValueOn(ijk));
            EXPECT_TRUE(nothing_but_occupancy(ijk)) << ijk;
            ++forgotten;
        } else {  // both: one vote of session 1, same sign as session 1's own evidence
            ASSERT_TRUE(after_acc.isValueOn(ijk));
            EXPECT_EQ(after_acc.getValue(ijk) > 0.0f, first_acc.getValue(ijk) > 0.0f);
            if (after_acc.getValue(ijk) > 0.0f) {  // still occupied: its semantics stay
                EXPECT_EQ(after.label->tree().getValue(ijk), before.label->tree().getValue(ijk));
                EXPECT_EQ(after.endpoints->tree().isValueOn(ijk),
                          before.endpoints->tree().isValueOn(ijk));
                ++both_occupied;
            } else {  // free now: no label, no endpoint
                EXPECT_TRUE(nothing_but_occupancy(ijk)) << ijk;
                ++both_free;
            }
        }
    }
    EXPECT_GT(kept, 1000u);
    EXPECT_GT(forgotten, 1000u);
    EXPECT_GT(both_free, 1000u);
    EXPECT_GT(both_occupied + both_free, 1000u);
    for (const LayerFile& layer : latest.layers) EXPECT_EQ(layer.session, 1);
    EXPECT_FALSE(map.SessionLayers(2).empty());  // kept for history until gc drops them
    // History still holds the session.
    ExpectSameMap(map.LoadMap(map.AsOf(2)), before);
    EXPECT_TRUE(ThrowsNaming<NotFoundError>([&] { (void)map.RemoveSession(2); }, "not in the map"));
    // Removing the last session empties the map.
    (void)map.RemoveSession(1);
    EXPECT_TRUE(map.Latest().tiles.empty());
    EXPECT_EQ(map.LoadMap(map.Latest()).occupancy->activeVoxelCount(), 0u);
    EXPECT_TRUE(map.Check().ok());
}

// The rule the map was built with decides the rebuild, not the defaults: a voxel both sessions
// saw keeps exactly one vote of the remaining session, with the map's hit and miss.
TEST(Store, RemovingASessionFusesWithTheMapsRule) {
    IntegrationConfig rule;
    rule.prob_hit = 0.8;
    rule.prob_miss = 0.3;
    const fs::path dir = Temp("remove_rule");
    MapStore map = NewMap(dir, rule);
    const auto first = Session(1, {0, 0, 0});
    (void)Write(map, first, {}, rule);
    (void)Write(map, Session(10, {2.0, 0.0, 0.0}), {}, rule);
    (void)map.RemoveSession(2);
    const VoxelMap after = map.LoadMap(map.Latest());
    const VoxelMap only_first = InMemory({first}, rule);
    const VoxelMap only_second = InMemory({Session(10, {2.0, 0.0, 0.0})}, rule);
    auto first_acc = only_first.occupancy->getConstAccessor();
    auto second_acc = only_second.occupancy->getConstAccessor();
    size_t both = 0;
    for (auto it = after.occupancy->cbeginValueOn(); it; ++it) {
        if (!second_acc.isValueOn(it.getCoord()) || !first_acc.isValueOn(it.getCoord())) continue;
        const float vote = first_acc.getValue(it.getCoord()) > 0.0f ? core::LogOdds(rule.prob_hit)
                                                                    : core::LogOdds(rule.prob_miss);
        EXPECT_EQ(*it, vote) << it.getCoord();
        ++both;
    }
    EXPECT_GT(both, 1000u);
    // A writer with another rule is refused before anything is written, naming the field.
    EXPECT_TRUE(ThrowsNaming<InvalidArgumentError>(
        [&] { (void)SessionWriter(map, IntegrationConfig{}, {}); }, "prob_hit: the map's 0.8"));
}

TEST(Store, OneWriterAtATimeAndReadersKeepTheirSnapshot) {
    const fs::path dir = Temp("lock");
    MapStore writer = NewMap(dir);
    EXPECT_TRUE(ThrowsNaming([&] { (void)MapStore::Open(dir, MapStore::Access::kWrite); },
                             "another strata process"));
    (void)Write(writer, Session(1, {0, 0, 0}));
    MapStore reader = MapStore::Open(dir, MapStore::Access::kRead);
    const auto snapshot = reader.Latest();
    const VoxelMap seen = reader.LoadMap(snapshot);
    (void)Write(writer, Session(10, {2.0, 0.0, 0.0}));
    // The old snapshot reads the same files, which nobody modified.
    ExpectSameMap(reader.LoadMap(snapshot), seen);
    EXPECT_EQ(reader.Latest().sessions.size(), 2u);
    EXPECT_THROW((void)SessionWriter(reader, IntegrationConfig{}, SessionOptions{}),
                 InvalidArgumentError);
    { MapStore released = std::move(writer); }
    EXPECT_NO_THROW((void)MapStore::Open(dir, MapStore::Access::kWrite));
}

TEST(Store, ReadersSeeWholeCommitsWhileAWriterCommits) {
    const fs::path dir = Temp("concurrent");
    const std::vector<std::vector<Scan>> sessions = {
        Session(1, {0, 0, 0}, 2), Session(10, {3, 1, 0}, 2), Session(20, {-2, -1, 0}, 2)};
    std::vector<VoxelMap> expected;  // the map after k sessions
    for (size_t k = 0; k <= sessions.size(); ++k) {
        expected.push_back(InMemory({sessions.begin(), sessions.begin() + static_cast<long>(k)}));
    }
    MapStore writer = NewMap(dir);
    std::atomic<bool> done{false};
    std::vector<size_t> seen;  // session counts the reader observed
    std::thread reader([&] {
        const MapStore map = MapStore::Open(dir, MapStore::Access::kRead);
        while (!done.load()) {
            const auto snapshot = map.Latest();
            const size_t n = snapshot.sessions.size();
            ExpectSameMap(map.LoadMap(snapshot), expected.at(n));
            seen.push_back(n);
        }
    });
    for (const auto& scans : sessions) (void)Write(writer, scans);
    done = true;
    reader.join();
    ASSERT_FALSE(seen.empty());
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
}

TEST(Store, AFailedCommitLeavesThePreviousCommitAndNoFiles) {
    for (const std::string step : {"tiles_written", "tiles_synced", "catalog_written"}) {
        const fs::path dir = Temp("fault_" + step);
        MapStore map = NewMap(dir);
        (void)Write(map, Session(1, {0, 0, 0}));
        const auto before = map.Latest();
        const VoxelMap before_map = map.LoadMap(before);
        SessionOptions options;
        options.fault_hook = [&](const std::string& at) {
            if (at == step) throw std::runtime_error("injected failure at " + at);
        };
        EXPECT_TRUE(ThrowsNaming(
            [&] {
                (void)Write(map, Session(10, {2, 0, 0}), options);
            },
            "injected failure at " + step));
        const auto after = map.Latest();
        EXPECT_EQ(after.commit, before.commit) << step;
        EXPECT_EQ(after.sessions.size(), 1u) << step;
        ExpectSameMap(map.LoadMap(after), before_map);
        const auto report = map.Check();
        EXPECT_TRUE(report.ok()) << step;
        EXPECT_TRUE(report.unreferenced.empty()) << step;
        // The next session gets the next id and works.
        EXPECT_EQ(Write(map, Session(20, {1, 1, 0})).id, 2) << step;
    }
}

TEST(Store, DamagedTilesAreNamedAndOthersStillRead) {
    const fs::path dir = Temp("damaged");
    MapStore map = NewMap(dir);
    (void)Write(map, Session(1, {0, 0, 0}));
    const auto tiles = map.Latest().tiles;
    ASSERT_GE(tiles.size(), 3u);
    const fs::path flipped = dir / tiles[0].file;
    const fs::path cut = dir / tiles[1].file;
    {
        std::fstream f(flipped, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(static_cast<std::streamoff>(tiles[0].bytes / 2));
        f.put('\x5a' ^ static_cast<char>(f.peek()));
    }
    fs::resize_file(cut, 8);  // OpenVDB would read a bare header as a valid, empty file
    EXPECT_TRUE(
        ThrowsNaming<FormatError>([&] { (void)map.ReadFused(tiles[0]); }, flipped.string()));
    EXPECT_TRUE(ThrowsNaming<FormatError>([&] { (void)map.ReadFused(tiles[0]); }, "checksum"));
    EXPECT_TRUE(ThrowsNaming<FormatError>([&] { (void)map.ReadFused(tiles[1]); }, "bytes"));
    EXPECT_NO_THROW((void)map.ReadFused(tiles[2]));
    EXPECT_TRUE(ThrowsNaming([&] { (void)map.LoadMap(map.Latest()); }, "tiles/"));
    fs::remove(dir / tiles[2].file);
    EXPECT_TRUE(ThrowsNaming<NotFoundError>([&] { (void)map.ReadFused(tiles[2]); }, "missing"));
    const auto report = map.Check();
    std::set<std::string> named;
    for (const auto& problem : report.problems) named.insert(problem.file);
    EXPECT_EQ(named, (std::set<std::string>{tiles[0].file, tiles[1].file, tiles[2].file}));
    EXPECT_EQ(report.problems.size(), 3u);
}

// A tile whose grids' voxel size is not the map's (a file of another map put in its place, its
// checksum right) is refused naming the file; a size read back within an ulp is taken as the
// map's own (TileByTile.RegisterReadsTheWholeMapsPointsTileByTile holds that).
TEST(Store, ATileOfAnotherVoxelSizeIsRefusedNamingItsFile) {
    const fs::path dir = Temp("voxel_size"), other_dir = Temp("voxel_size_other");
    MapStore map = NewMap(dir);
    (void)Write(map, Session(1, {0, 0, 0}));
    StoreSettings coarse;
    coarse.voxel_size_m = 2 * kVoxel;
    coarse.tile_size_m = kTile;
    MapStore other = MapStore::Create(other_dir, coarse);
    (void)Write(other, Session(1, {0, 0, 0}));
    const TileVersion foreign = other.Latest().tiles.at(0);
    const fs::path placed = dir / foreign.file;
    fs::create_directories(placed.parent_path());
    fs::copy_file(other_dir / foreign.file, placed, fs::copy_options::overwrite_existing);
    EXPECT_TRUE(ThrowsNaming<FormatError>([&] { (void)map.ReadFused(foreign); }, placed.string()));
    EXPECT_TRUE(ThrowsNaming<FormatError>([&] { (void)map.ReadFused(foreign); }, "voxels of"));
    EXPECT_NO_THROW((void)other.ReadFused(foreign));
}

// A missing or damaged layer file is named by check; reading the fused map does not need it and
// still works; what needs it (removing that session) fails naming it and changes nothing.
TEST(Store, DamagedLayerFilesAreNamedAndOnlyWhatNeedsThemFails) {
    const fs::path dir = Temp("damaged_layers");
    MapStore map = NewMap(dir);
    (void)Write(map, Session(1, {0, 0, 0}));
    (void)Write(map, Session(10, {2, 0, 0}));
    const Snapshot before = map.Latest();
    const VoxelMap fused = map.LoadMap(before);
    const std::vector<LayerFile> layers = map.SessionLayers(2);
    ASSERT_GE(layers.size(), 2u);
    fs::remove(dir / layers[0].file);
    fs::resize_file(dir / layers[1].file, layers[1].bytes - 1);
    const CheckReport report = map.Check();
    std::set<std::string> named;
    for (const auto& p : report.problems) named.insert(p.file);
    EXPECT_EQ(named, (std::set<std::string>{layers[0].file, layers[1].file}));
    ExpectSameMap(map.LoadMap(map.Latest()), fused);
    EXPECT_TRUE(ThrowsNaming([&] { (void)map.RemoveSession(2); }, "tiles/"));
    EXPECT_EQ(map.Latest().commit, before.commit);
    EXPECT_TRUE(map.Check().unreferenced.empty());
}

TEST(Store, NewerFormatsAndForeignFilesAreRefused) {
    const fs::path dir = Temp("newer");
    { (void)NewMap(dir); }
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((dir / "catalog.sqlite").c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, "PRAGMA user_version = 99", nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(db);
    for (const auto access : {MapStore::Access::kRead, MapStore::Access::kWrite}) {
        EXPECT_TRUE(ThrowsNaming<FormatError>([&] { (void)MapStore::Open(dir, access); }, "newer"));
    }
    const fs::path garbage = Temp("garbage");
    fs::create_directories(garbage);
    std::ofstream(garbage / "catalog.sqlite") << "this is not a database";
    EXPECT_TRUE(ThrowsNaming([&] { (void)MapStore::Open(garbage, MapStore::Access::kRead); },
                             (garbage / "catalog.sqlite").string()));
}

TEST(Store, ReadOnlyMapsOpenForReadingOnly) {
    const fs::path dir = Temp("readonly");
    {
        MapStore map = NewMap(dir);
        (void)Write(map, Session(1, {0, 0, 0}));
    }
    fs::permissions(dir, fs::perms::owner_write | fs::perms::group_write | fs::perms::others_write,
                    fs::perm_options::remove);
    fs::permissions(dir / "catalog.sqlite",
                    fs::perms::owner_write | fs::perms::group_write | fs::perms::others_write,
                    fs::perm_options::remove);
    EXPECT_TRUE(ThrowsNaming<IoError>([&] { (void)MapStore::Open(dir, MapStore::Access::kWrite); },
                                      "read-only"));
    const MapStore map = MapStore::Open(dir, MapStore::Access::kRead);
    EXPECT_EQ(map.Latest().sessions.size(), 1u);
    fs::permissions(dir, fs::perms::owner_write, fs::perm_options::add);
    fs::permissions(dir / "catalog.sqlite", fs::perms::owner_write, fs::perm_options::add);
}

// A fuzz finding (fuzz_catalog, docs/reliability.md). Opening a map whose catalog.sqlite is not a
// database threw from inside the Database constructor, whose destructor then never closed the
// SQLite connection: one file descriptor lost per refused catalog, until fuzz_catalog could not
// open files any more (after 23000).
size_t OpenFileDescriptors() {
    size_t n = 0;
    for (const auto& entry : fs::directory_iterator("/proc/self/fd")) n += entry.exists() ? 1 : 0;
    return n;
}

TEST(MapStoreFuzzFindings, RefusingADamagedCatalogClosesIt) {
    const fs::path map = Temp("damaged_catalog");
    fs::create_directories(map / "tiles");
    std::ofstream(map / "catalog.sqlite") << std::string(4096, 'x');
    const size_t before = OpenFileDescriptors();
    for (int i = 0; i < 20; ++i) {
        EXPECT_THROW((void)MapStore::Open(map, MapStore::Access::kRead), std::runtime_error);
    }
    EXPECT_EQ(OpenFileDescriptors(), before);
}

}  // namespace
}  // namespace strata::store::test
