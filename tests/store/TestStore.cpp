// The store: commits, snapshots, session layers, eviction, removal, locking and damaged files,
// on synthetic scans whose in-memory integration is the known answer.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <thread>

#include "MapDiff.hpp"
#include "TempPath.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/store/MapStore.hpp"
#include "strata/store/SessionWriter.hpp"

namespace {

namespace fs = std::filesystem;
using strata::core::Scan;
using strata::core::VoxelMap;
using strata::integration::IntegrationConfig;
using strata::store::MapStore;
using strata::store::SessionOptions;
using strata::store::SessionWriter;
using strata::store::StoreSettings;

constexpr double kVoxel = 0.1;
constexpr double kTile = 3.2;  // 32 voxels: a 12 m room spans many tiles

fs::path Temp(const std::string& name) { return strata::test::TempPath("store_" + name); }

// A 12 x 8 x 3 m room around `centre`, with labelled points (floor road, the rest building).
Scan RoomScan(uint32_t seed, const Eigen::Vector3d& centre, size_t n = 6000) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Scan scan;
    scan.T_world_sensor.translation() = centre;
    for (size_t i = 0; i < n; ++i) {
        // z, y, x, one draw each: argument order is unspecified (gcc right to left, clang left to
        // right) and the scan must not depend on the compiler; this is the order gcc always used.
        Eigen::Vector3d d;
        d.z() = u(rng);
        d.y() = u(rng);
        d.x() = u(rng);
        const Eigen::Array3d half(6.0, 4.0, 1.5);
        const double t = (half / d.array().abs()).minCoeff();
        scan.points.push_back(d * t);
        scan.labels.push_back(std::abs(d.z() * t + 1.5) < 1e-9
                                  ? strata::core::SemanticClass::kGround
                                  : strata::core::SemanticClass::kBuilding);
    }
    scan.source = "room_" + std::to_string(seed);
    scan.time_s = seed * 0.1;
    return scan;
}

std::vector<Scan> Session(uint32_t first_seed, const Eigen::Vector3d& start, size_t scans = 3) {
    std::vector<Scan> out;
    for (size_t k = 0; k < scans; ++k) {
        out.push_back(RoomScan(first_seed + static_cast<uint32_t>(k),
                               start + Eigen::Vector3d(0.7 * static_cast<double>(k), 0.3, 0.1)));
    }
    return out;
}

SessionOptions Named(const std::string& name) {
    SessionOptions options;
    options.name = name;
    return options;
}

MapStore NewMap(const fs::path& dir) {
    StoreSettings settings;
    settings.voxel_size_m = kVoxel;
    settings.tile_size_m = kTile;
    return MapStore::Create(dir, settings);
}

strata::store::SessionRecord Write(MapStore& map, const std::vector<Scan>& scans,
                                   SessionOptions options = {}) {
    SessionWriter writer(map, IntegrationConfig{}, std::move(options));
    for (const Scan& scan : scans) (void)writer.Integrate(scan);
    return writer.Commit();
}

// The reference: the same scans integrated into one in-memory map.
VoxelMap InMemory(const std::vector<std::vector<Scan>>& sessions) {
    VoxelMap map = VoxelMap::Create(kVoxel);
    strata::integration::Integrator integrator(map, IntegrationConfig{});
    for (const auto& scans : sessions) {
        for (const Scan& scan : scans) (void)integrator.Integrate(scan);
    }
    return map;
}

void ExpectSameMap(const VoxelMap& a, const VoxelMap& b) {
    EXPECT_EQ(strata::testing::MapDifference(a, b), "");
}

::testing::AssertionResult ThrowsNaming(const std::function<void()>& fn, const std::string& what) {
    try {
        fn();
    } catch (const std::exception& e) {
        if (std::string(e.what()).find(what) != std::string::npos) {
            return ::testing::AssertionSuccess();
        }
        return ::testing::AssertionFailure()
               << "message '" << e.what() << "' lacks '" << what << "'";
    }
    return ::testing::AssertionFailure() << "no exception";
}

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
    EXPECT_TRUE(ThrowsNaming([&] { (void)MapStore::Create(dir, settings); }, dir.string()));
    EXPECT_TRUE(
        ThrowsNaming([&] { (void)MapStore::Open(Temp("nothing"), MapStore::Access::kRead); },
                     "no such map directory"));
    const fs::path empty = Temp("empty");
    fs::create_directories(empty);
    EXPECT_TRUE(ThrowsNaming([&] { (void)MapStore::Open(empty, MapStore::Access::kRead); },
                             "not a strata map"));
}

TEST(Store, TileKeysFloorNegativeCoordinates) {
    strata::store::MapSettings s;
    s.tile_voxels = 32;
    EXPECT_EQ(s.TileOf({0, 31, 5}), (strata::store::TileKey{0, 0}));
    EXPECT_EQ(s.TileOf({-1, 32, 5}), (strata::store::TileKey{-1, 1}));
    EXPECT_EQ(s.TileOf({-32, -33, 5}), (strata::store::TileKey{-1, -2}));
    EXPECT_TRUE(s.TileBounds({-1, 1}).isInside(openvdb::Coord(-1, 32, -100000)));
}

TEST(Store, SessionsEqualInMemoryIntegrationAndSnapshotsGoBack) {
    const fs::path dir = Temp("sessions");
    const auto first = Session(1, {0, 0, 0});
    const auto second = Session(10, {4.0, 1.0, 0.0});
    {
        MapStore map = NewMap(dir);
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
    EXPECT_TRUE(ThrowsNaming([&] { (void)map.FindSession("nope"); }, "no session 'nope'"));
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
            EXPECT_EQ(after.tiles[i].key, (strata::store::TileKey{0, 0}));
        } else {
            EXPECT_EQ(after.tiles[i].file, before.tiles[i].file);
        }
    }
    EXPECT_EQ(rewritten, 1u);
}

TEST(Store, SessionLayersSayWhatEachSessionSaw) {
    const fs::path dir = Temp("layers");
    MapStore map = NewMap(dir);
    const auto first = Session(1, {0, 0, 0});
    (void)Write(map, first);
    (void)Write(map, Session(10, {4.0, 1.0, 0.0}));
    const VoxelMap only_first = InMemory({first});
    size_t occupied = 0;
    for (const auto& version : map.Latest().tiles) {
        const strata::store::Tile tile = map.ReadTile(version);
        ASSERT_FALSE(tile.layers.empty());
        for (const auto& layer : tile.layers) {
            EXPECT_EQ(layer.occupied->getName(),
                      "session_" + std::to_string(layer.session) + "_occupied");
            // Disjoint, and inside what the fused map observed.
            auto free = layer.free->getConstAccessor();
            auto fused = tile.fused.occupancy->getConstAccessor();
            EXPECT_EQ(layer.occupied->tree().activeTileCount(), 0u);
            for (auto it = layer.occupied->cbeginValueOn(); it; ++it) {
                EXPECT_TRUE(*it);
                EXPECT_FALSE(free.isValueOn(it.getCoord()));
                EXPECT_TRUE(fused.isValueOn(it.getCoord()));
            }
        }
        // Session 1's layers are its own integration, thresholded.
        if (tile.layers.front().session != 1) continue;
        auto ref = only_first.occupancy->getConstAccessor();
        for (auto it = tile.layers.front().occupied->cbeginValueOn(); it; ++it) {
            EXPECT_GT(ref.getValue(it.getCoord()), 0.0f);
            ++occupied;
        }
        for (auto it = tile.layers.front().free->cbeginValueOn(); it; ++it) {
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
    size_t kept = 0, forgotten = 0;
    for (auto it = before.occupancy->cbeginValueOn(); it; ++it) {
        const openvdb::Coord ijk = it.getCoord();
        const bool seen1 = first_acc.isValueOn(ijk), seen2 = second_acc.isValueOn(ijk);
        if (!seen2) {  // untouched by the removed session: bit-identical
            EXPECT_EQ(after_acc.getValue(ijk), *it);
            ++kept;
        } else if (!seen1) {  // only the removed session saw it: unknown again
            EXPECT_FALSE(after_acc.isValueOn(ijk));
            ++forgotten;
        } else {  // both: one vote of session 1, same sign as session 1's own evidence
            ASSERT_TRUE(after_acc.isValueOn(ijk));
            EXPECT_EQ(after_acc.getValue(ijk) > 0.0f, first_acc.getValue(ijk) > 0.0f);
        }
    }
    EXPECT_GT(kept, 1000u);
    EXPECT_GT(forgotten, 1000u);
    for (const auto& version : latest.tiles) {
        for (const auto& layer : map.ReadTile(version).layers) EXPECT_EQ(layer.session, 1);
    }
    // History still holds the session.
    ExpectSameMap(map.LoadMap(map.AsOf(2)), before);
    EXPECT_TRUE(ThrowsNaming([&] { (void)map.RemoveSession(2); }, "not in the map"));
    // Removing the last session empties the map.
    (void)map.RemoveSession(1);
    EXPECT_TRUE(map.Latest().tiles.empty());
    EXPECT_EQ(map.LoadMap(map.Latest()).occupancy->activeVoxelCount(), 0u);
    EXPECT_TRUE(map.Check().ok());
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
                 std::logic_error);
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
    EXPECT_TRUE(ThrowsNaming([&] { (void)map.ReadTile(tiles[0]); }, flipped.string()));
    EXPECT_TRUE(ThrowsNaming([&] { (void)map.ReadTile(tiles[0]); }, "checksum"));
    EXPECT_TRUE(ThrowsNaming([&] { (void)map.ReadTile(tiles[1]); }, "bytes"));
    EXPECT_NO_THROW((void)map.ReadTile(tiles[2]));
    EXPECT_TRUE(ThrowsNaming([&] { (void)map.LoadMap(map.Latest()); }, "tiles/"));
    fs::remove(dir / tiles[2].file);
    const auto report = map.Check();
    std::set<std::string> named;
    for (const auto& problem : report.problems) named.insert(problem.file);
    EXPECT_EQ(named, (std::set<std::string>{tiles[0].file, tiles[1].file, tiles[2].file}));
    EXPECT_EQ(report.problems.size(), 3u);
}

TEST(Store, NewerFormatsAndForeignFilesAreRefused) {
    const fs::path dir = Temp("newer");
    { (void)NewMap(dir); }
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((dir / "catalog.sqlite").c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, "PRAGMA user_version = 99", nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(db);
    for (const auto access : {MapStore::Access::kRead, MapStore::Access::kWrite}) {
        EXPECT_TRUE(ThrowsNaming([&] { (void)MapStore::Open(dir, access); }, "newer"));
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
    EXPECT_TRUE(
        ThrowsNaming([&] { (void)MapStore::Open(dir, MapStore::Access::kWrite); }, "read-only"));
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

// A product grid over the room (several tiles): value `value` on the occupied voxels of z = 0.
openvdb::FloatGrid::Ptr ProductOver(const VoxelMap& map, float value) {
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("slant_deg");
    grid->setTransform(VoxelMap::MakeTransform(kVoxel));
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it > 0.0f && it.getCoord().z() == 0) grid->tree().setValueOn(it.getCoord(), value);
    }
    return grid;
}

size_t ProductVoxels(const MapStore& map, const std::string& name) {
    size_t n = 0;
    for (const auto& v : map.Latest().tiles) {
        for (const auto& g : map.ReadTile(v).products)
            n += g->getName() == name ? g->activeVoxelCount() : 0;
    }
    return n;
}

TEST(Store, AnalysisProductsReplaceTheirGridsInOneCommit) {
    const fs::path dir = Temp("products");
    MapStore map = NewMap(dir);
    (void)Write(map, Session(1, {0, 0, 0}));
    const auto before = map.Latest();
    const VoxelMap fused = map.LoadMap(before);
    const auto first = ProductOver(fused, 88.0f);
    ASSERT_GT(first->activeVoxelCount(), 100u);
    strata::store::WallRecord wall;
    wall.wall_id = 1;
    wall.slant_deg = 88.0;
    wall.inliers = 42;
    const int64_t c1 = map.CommitProducts("walls", {first}, {wall, wall});
    EXPECT_GT(c1, before.commit);
    EXPECT_EQ(ProductVoxels(map, "slant_deg"), first->activeVoxelCount());
    ASSERT_EQ(map.Walls().size(), 2u);
    EXPECT_EQ(map.Walls()[0].commit, c1);
    EXPECT_EQ(map.Walls()[0].inliers, 42u);
    // The fused map and the sessions are untouched; the map as of the session has no products.
    ExpectSameMap(map.LoadMap(map.Latest()), fused);
    EXPECT_EQ(map.Latest().sessions.size(), 1u);
    for (const auto& v : map.AsOf(1).tiles) EXPECT_TRUE(map.ReadTile(v).products.empty());
    // A second run replaces the grid and the rows, it does not add to them.
    auto second = openvdb::FloatGrid::create(0.0f);
    second->setName("slant_deg");
    second->setTransform(VoxelMap::MakeTransform(kVoxel));
    second->tree().setValueOn(openvdb::Coord(1, 1, 0), 90.0f);
    (void)map.CommitProducts("walls", {second}, {wall});
    EXPECT_EQ(ProductVoxels(map, "slant_deg"), 1u);
    EXPECT_EQ(map.Walls().size(), 1u);
    EXPECT_TRUE(map.Check().ok());
    // A session integrated later keeps the products as they were.
    (void)Write(map, Session(5, {1, 0, 0}));
    EXPECT_EQ(ProductVoxels(map, "slant_deg"), 1u);
}

TEST(Store, AFailedProductCommitLeavesTheMapAsItWas) {
    const fs::path dir = Temp("products_fail");
    MapStore map = NewMap(dir);
    (void)Write(map, Session(1, {0, 0, 0}));
    const auto before = map.Latest();
    const size_t files = map.TileFileCount();
    auto misaligned = ProductOver(map.LoadMap(before), 1.0f);
    misaligned->setTransform(VoxelMap::MakeTransform(2 * kVoxel));
    EXPECT_TRUE(
        ThrowsNaming([&] { (void)map.CommitProducts("walls", {misaligned}); }, "not aligned"));
    EXPECT_THROW((void)map.CommitProducts("paint", {}), std::invalid_argument);
    // A tile that cannot be written (its folder is read-only) fails the whole commit.
    const fs::path tile_dir = (dir / before.tiles.back().file).parent_path();
    fs::permissions(tile_dir, fs::perms::owner_write, fs::perm_options::remove);
    const bool enforced = ::access(tile_dir.c_str(), W_OK) != 0;  // root ignores permissions
    if (enforced) {
        EXPECT_THROW((void)map.CommitProducts("walls", {ProductOver(map.LoadMap(before), 1.0f)}),
                     std::runtime_error);
    }
    fs::permissions(tile_dir, fs::perms::owner_write, fs::perm_options::add);
    EXPECT_EQ(map.Latest().commit, before.commit);
    EXPECT_EQ(map.TileFileCount(), files);
    EXPECT_TRUE(map.Walls().empty());
    const auto report = map.Check();
    EXPECT_TRUE(report.ok());
    EXPECT_TRUE(report.unreferenced.empty());
    MapStore reader = MapStore::Open(dir, MapStore::Access::kRead);
    EXPECT_THROW((void)reader.CommitProducts("walls", {}), std::logic_error);
}

TEST(Store, AnEditOfTheFusedMapIsOneCommitAndTheSessionsStayAsScanned) {
    const fs::path dir = Temp("edit");
    MapStore map = NewMap(dir);
    (void)Write(map, Session(1, {0, 0, 0}));
    const auto before = map.Latest();
    const VoxelMap original = map.LoadMap(before);
    // The edit: occupied voxels at z = 0 removed (a vehicle cleared), one new voxel written
    // past the edge of the scanned room (a refill reaching a tile with no data).
    VoxelMap edited = original.DeepCopy();
    auto cleared = openvdb::Int32Grid::create(0);
    cleared->setName("vehicle_cleared");
    cleared->setTransform(VoxelMap::MakeTransform(kVoxel));
    for (auto it = original.occupancy->cbeginValueOn(); it; ++it) {
        if (*it <= 0.0f || it.getCoord().z() != 0) continue;
        edited.occupancy->tree().setValueOff(it.getCoord(), 0.0f);
        cleared->tree().setValueOn(it.getCoord(), 7);
    }
    const openvdb::Coord far(500, 500, 0);
    edited.occupancy->tree().setValueOn(far, 0.85f);
    cleared->tree().setValueOn(far, 8);
    ASSERT_GT(cleared->activeVoxelCount(), 100u);
    const VoxelMap expected = edited.DeepCopy();
    strata::store::VehicleRecord car;
    car.vehicle_id = 7;
    car.source = "geometric";
    car.size = {4.5, 1.8, 1.5};
    car.cleared_voxels = cleared->activeVoxelCount();
    const int64_t commit = map.CommitEdit("vehicles", edited, {cleared}, {car});
    EXPECT_GT(commit, before.commit);
    ExpectSameMap(map.LoadMap(map.Latest()), expected);
    ExpectSameMap(map.LoadMap(map.AsOf(1)), original);  // the map as scanned is still there
    ASSERT_EQ(map.Vehicles().size(), 1u);
    EXPECT_EQ(map.Vehicles()[0].vehicle_id, 7);
    EXPECT_EQ(map.Vehicles()[0].source, "geometric");
    EXPECT_EQ(map.Vehicles()[0].size.x(), 4.5);
    EXPECT_EQ(ProductVoxels(map, "vehicle_cleared"), cleared->activeVoxelCount());
    EXPECT_TRUE(map.Check().ok());
    // A wrong voxel size is refused before anything is written.
    VoxelMap coarse = VoxelMap::Create(2 * kVoxel);
    EXPECT_THROW((void)map.CommitEdit("vehicles", coarse, {}, {}), std::invalid_argument);
    EXPECT_EQ(map.Latest().commit, commit);
    // Later sessions integrate on top of the edited map.
    EXPECT_EQ(Write(map, Session(5, {1, 0, 0})).id, 2);
    EXPECT_TRUE(map.Check().ok());
}

TEST(Store, MigratesAFormat2CatalogToTheCurrentFormat) {
    const fs::path dir = Temp("migrate");
    {
        MapStore map = NewMap(dir);
        (void)Write(map, Session(1, {0, 0, 0}));
    }
    // Put the catalog back to format 2: the commits CHECK and the walls table of that version.
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((dir / "catalog.sqlite").c_str(), &db), SQLITE_OK);
    const char* downgrade = R"sql(
CREATE TABLE commits_v2 (id INTEGER PRIMARY KEY AUTOINCREMENT, time_utc TEXT NOT NULL,
  session_id INTEGER,
  kind TEXT NOT NULL CHECK (kind IN ('create', 'integrate', 'remove_session')));
INSERT INTO commits_v2 SELECT id, time_utc, session_id, kind FROM commits;
DROP TABLE commits;
ALTER TABLE commits_v2 RENAME TO commits;
DROP TABLE walls;
CREATE TABLE walls (id INTEGER PRIMARY KEY AUTOINCREMENT,
  commit_id INTEGER NOT NULL REFERENCES commits(id), center_x REAL, center_y REAL, center_z REAL,
  normal_x REAL, normal_y REAL, normal_z REAL, slant_deg REAL, length_m REAL, height_m REAL,
  points INTEGER);
PRAGMA user_version = 2;
UPDATE settings SET value = '2' WHERE key = 'format_version';
)sql";
    ASSERT_EQ(sqlite3_exec(db, downgrade, nullptr, nullptr, nullptr), SQLITE_OK)
        << sqlite3_errmsg(db);
    sqlite3_close(db);
    {
        const MapStore old = MapStore::Open(dir, MapStore::Access::kRead);
        EXPECT_EQ(old.settings().format_version, 2);
        EXPECT_TRUE(old.Walls().empty());  // readers do not migrate
    }
    MapStore map = MapStore::Open(dir, MapStore::Access::kWrite);
    EXPECT_EQ(map.settings().format_version, MapStore::kFormatVersion);
    EXPECT_EQ(map.Latest().sessions.size(), 1u);
    const int64_t commit = map.CommitProducts("walls", {}, {strata::store::WallRecord{}});
    EXPECT_EQ(map.Walls().size(), 1u);
    EXPECT_GT(commit, map.Latest().sessions[0].commit);
    EXPECT_TRUE(map.Vehicles().empty());  // format 4's vehicles table, empty
    EXPECT_EQ(Write(map, Session(5, {1, 0, 0})).id, 2);
}

}  // namespace
