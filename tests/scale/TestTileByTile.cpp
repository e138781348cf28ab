// Commands that read a map tile by tile answer what reading it whole answers (docs/scale.md).
#include <gtest/gtest.h>
#include <openvdb/io/File.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>

#include "StoreTestUtil.hpp"
#include "strata/change/MapObserver.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/pipeline/Alignment.hpp"
#include "strata/pipeline/Export.hpp"
#include "strata/pipeline/Info.hpp"
#include "strata/registration/MapRegion.hpp"
#include "strata/registration/Register.hpp"

namespace strata::pipeline {
namespace {

namespace fs = std::filesystem;

TEST(TileByTile, InfoCountsEqualTheWholeMapsCounts) {
    store::MapStore map = store::test::NewMapOfManyTiles(store::test::Temp("tiles_info"));
    (void)store::test::Write(map, store::test::Session(1, {0.4, 0.2, 0.0}, 3));
    (void)store::test::Write(map, store::test::Session(9, {3.1, -1.7, 0.3}, 2));
    const nlohmann::json j = DescribeMap(map, "");
    ASSERT_GT(j["tiles"].get<size_t>(), 20u);  // 3.2 m tiles: the rooms span many
    const core::VoxelMap whole = map.LoadMap(map.Latest());
    size_t occupied = 0, free = 0;
    std::map<std::string, size_t> classes;
    auto label = whole.label->getConstAccessor();
    for (auto it = whole.occupancy->cbeginValueOn(); it; ++it) {
        if (*it > 0.0f) {
            ++occupied;
            int32_t v = 0;
            ++classes[core::ClassName(label.probeValue(it.getCoord(), v)
                                          ? static_cast<core::SemanticClass>(v)
                                          : core::SemanticClass::kUnknown)];
        } else {
            ++free;
        }
    }
    EXPECT_EQ(j["occupied_voxels"].get<size_t>(), occupied);
    EXPECT_EQ(j["free_voxels"].get<size_t>(), free);
    using Counts = std::map<std::string, size_t>;
    EXPECT_EQ(j["classes"].get<Counts>(), classes);
    EXPECT_EQ(classes.size(), 2u);  // ground and building
    const openvdb::CoordBBox box = whole.occupancy->evalActiveVoxelBoundingBox();
    const double s = whole.voxel_size;
    EXPECT_NEAR(j["extent_min"][0].get<double>(), box.min().x() * s, 1e-3);
    EXPECT_NEAR(j["extent_max"][2].get<double>(), (box.max().z() + 1) * s, 1e-3);
    // As of the first session too.
    const nlohmann::json first = DescribeMap(map, "1");
    EXPECT_LT(first["occupied_voxels"].get<size_t>(), occupied);
    EXPECT_EQ(first["commit"].get<int64_t>(), map.AsOf(1).commit);
}

// A PLY file's header and its vertex records sorted (tile order and tree order differ; the set
// of vertices is what must be equal).
std::pair<std::string, std::vector<std::string>> PlyVertices(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream all;
    all << in.rdbuf();
    const std::string bytes = all.str();
    const size_t end = bytes.find("end_header\n") + 11;
    const size_t record = 3 * sizeof(float) + 4;  // x y z, red green blue, label
    std::vector<std::string> vertices;
    for (size_t at = end; at + record <= bytes.size(); at += record) {
        vertices.push_back(bytes.substr(at, record));
    }
    EXPECT_EQ((bytes.size() - end) % record, 0u);
    std::sort(vertices.begin(), vertices.end());
    return {bytes.substr(0, end), vertices};
}

store::MapStore TwoRooms(const std::string& name) {
    store::MapStore map = store::test::NewMapOfManyTiles(store::test::Temp(name));
    (void)store::test::Write(map, store::test::Session(1, {0.4, 0.2, 0.0}, 3));
    (void)store::test::Write(map, store::test::Session(9, {3.1, -1.7, 0.3}, 2));
    return map;
}

TEST(TileByTile, PlyStreamsTheWholeMapsVertices) {
    const store::MapStore map = TwoRooms("tiles_ply");
    const fs::path streamed = store::test::Temp("tiles_streamed.ply");
    const fs::path whole = store::test::Temp("tiles_whole.ply");
    const ExportResult result = ExportStored(map, map.Latest(), streamed);
    EXPECT_EQ(result.tiles_read, 2 * map.Latest().tiles.size());
    (void)ExportMap(map.LoadMap(map.Latest()), whole);
    const auto [header_s, vertices_s] = PlyVertices(streamed);
    const auto [header_w, vertices_w] = PlyVertices(whole);
    EXPECT_EQ(header_s, header_w);  // the same count, properties and comments
    EXPECT_GT(vertices_w.size(), 1000u);
    EXPECT_TRUE(vertices_s == vertices_w);
}

TEST(TileByTile, SplitVdbWritesEveryTileAndAnIndex) {
    const store::MapStore map = TwoRooms("tiles_split");
    const fs::path out = store::test::Temp("tiles_split_out") / "city.vdb";
    fs::create_directories(out.parent_path());
    ExportOptions options;
    options.split = true;
    const ExportResult result = ExportStored(map, map.Latest(), out, options);
    const size_t tiles = map.Latest().tiles.size();
    ASSERT_EQ(result.files.size(), tiles + 1);
    std::ifstream in(out.parent_path() / "city.tiles.json");
    const nlohmann::json index = nlohmann::json::parse(in);
    ASSERT_EQ(index["tiles"].size(), tiles);
    EXPECT_EQ(index["format"], "vdb");
    // Every tile file holds its tile's occupancy; together they are the map's.
    size_t voxels = 0;
    for (const auto& t : index["tiles"]) {
        openvdb::io::File file((out.parent_path() / t["file"].get<std::string>()).string());
        file.open();
        const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("occupancy"));
        voxels += grid->activeVoxelCount();
        const double t0 = t["bounds_m"][0].get<double>(), t1 = t["bounds_m"][2].get<double>();
        const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
        EXPECT_GE(box.min().x() * map.settings().voxel_size_m, t0 - 1e-9);
        EXPECT_LE((box.max().x() + 1) * map.settings().voxel_size_m, t1 + 1e-9);
    }
    EXPECT_EQ(voxels, map.LoadMap(map.Latest()).occupancy->activeVoxelCount());
}

TEST(TileByTile, AWholeMapExportOverTheBudgetIsRefusedBeforeAnythingIsWritten) {
    const store::MapStore map = TwoRooms("tiles_budget");
    const fs::path out = store::test::Temp("tiles_budget.vdb");
    ExportOptions options;
    options.memory_budget_bytes = 1000;
    try {
        (void)ExportStored(map, map.Latest(), out, options);
        ADD_FAILURE() << "not refused";
    } catch (const RefusedError& e) {
        EXPECT_NE(std::string(e.what()).find("--split"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(out));
    options.format = "ply";  // PLY streams whatever the budget
    const fs::path ply = store::test::Temp("tiles_budget.ply");
    (void)ExportStored(map, map.Latest(), ply, options);
    EXPECT_GT(fs::file_size(ply), 1000u);
}

void ExpectSameChanges(const change::ChangeSet& tiled, const change::ChangeSet& whole) {
    EXPECT_EQ(tiled.unknown_voxels, whole.unknown_voxels);
    EXPECT_EQ(tiled.added_voxels_total, whole.added_voxels_total);
    EXPECT_EQ(tiled.removed_voxels_total, whole.removed_voxels_total);
    EXPECT_TRUE(tiled.added->tree().hasSameTopology(whole.added->tree()));
    EXPECT_TRUE(tiled.removed->tree().hasSameTopology(whole.removed->tree()));
    ASSERT_EQ(tiled.objects.size(), whole.objects.size());
    for (size_t i = 0; i < whole.objects.size(); ++i) {
        const change::ChangeObject &t = tiled.objects[i], &w = whole.objects[i];
        EXPECT_EQ(t.id, w.id);
        EXPECT_EQ(t.kind, w.kind);
        EXPECT_EQ(t.voxels, w.voxels);
        EXPECT_EQ(t.bbox_min, w.bbox_min);
        EXPECT_EQ(t.bbox_max, w.bbox_max);
        EXPECT_EQ(t.centroid, w.centroid);  // bit for bit: voxels summed in one order
        EXPECT_EQ(t.oriented.yaw_deg, w.oriented.yaw_deg);
        EXPECT_EQ(t.dominant_class, w.dominant_class);
    }
}

TEST(TileByTile, ChangesReadTileByTileAreTheWholeMapsChanges) {
    const store::MapStore map = TwoRooms("tiles_diff");
    change::MapObserver observer(map);
    // Two rooms 2.7 m apart in x, in 3.2 m tiles: each one's walls stand in the other's free
    // space, so changes cross many tile borders.
    change::ChangeQuery query;
    const change::ChangeSet whole =
        change::DetectChanges(observer.Session(1), observer.Session(2), 0.1, query);
    ASSERT_GE(whole.objects.size(), 3u);
    size_t tiles_crossed = 0;
    for (const change::ChangeObject& o : whole.objects) {
        tiles_crossed +=
            std::floor(o.bbox_min.x() / 3.2) != std::floor((o.bbox_max.x() - 1e-6) / 3.2);
    }
    EXPECT_GT(tiles_crossed, 0u);
    ExpectSameChanges(change::DetectChangesByTiles(observer.SessionSide(1), observer.SessionSide(2),
                                                   map.settings(), query),
                      whole);
    // Without growth, in a region, and between snapshots of the fused map.
    query.grow_voxels = 0;
    query.region = core::Region::Box(-1.0, -4.0, 6.0, 3.0);
    change::MapObserver in_region(map, query.region);
    ExpectSameChanges(
        change::DetectChangesByTiles(in_region.SessionSide(1), in_region.SessionSide(2),
                                     map.settings(), query),
        change::DetectChanges(in_region.Session(1), in_region.Session(2), 0.1, query));
    change::ChangeQuery maps;
    const change::ChangeSet whole_maps =
        change::DetectChanges(observer.Map(map.AsOf(1)), observer.Map(map.Latest()), 0.1, maps);
    ExpectSameChanges(
        change::DetectChangesByTiles(observer.MapSide(map.AsOf(1)), observer.MapSide(map.Latest()),
                                     map.settings(), maps),
        whole_maps);
    // A side already in memory (scans `strata diff` integrated but did not commit), cut per tile.
    ExpectSameChanges(
        change::DetectChangesByTiles(observer.MapSide(map.AsOf(1)),
                                     change::WholeSide(observer.Map(map.Latest()), map.settings()),
                                     map.settings(), maps),
        whole_maps);
}

// A scan like the first session's of TwoRooms, and a guess 0.3 m and 3 deg off (the rooms
// overlap, so where it lands is not the point here; registration's own tests hold the accuracy).
struct AlignmentCase {
    SourceCloud cloud;
    AlignOptions options;
    Eigen::Isometry3d guess = registration::PoseFromXyzYaw(0.7, 0.4, 0.1, 3.0);
};
AlignmentCase RoomAlignment() {
    AlignmentCase c;
    c.cloud.points = store::test::RoomScan(77, {0.4, 0.5, 0.1}).points;
    c.cloud.scans = 1;
    c.cloud.single_scan = true;
    c.options.min_range_m = 0.5;
    return c;
}

// `register` reads the map's occupied points tile by tile, sorted: the points of the whole map,
// and one alignment however the map is cut into tiles.
TEST(TileByTile, RegisterReadsTheWholeMapsPointsTileByTile) {
    const store::MapStore small = TwoRooms("tiles_register_small");
    store::StoreSettings settings;
    settings.voxel_size_m = store::test::kVoxel;
    settings.tile_size_m = 4 * store::test::kTile;
    store::MapStore large =
        store::MapStore::Create(store::test::Temp("tiles_register_large"), settings);
    (void)store::test::Write(large, store::test::Session(1, {0.4, 0.2, 0.0}, 3));
    (void)store::test::Write(large, store::test::Session(9, {3.1, -1.7, 0.3}, 2));
    ASSERT_GT(small.Latest().tiles.size(), 4 * large.Latest().tiles.size());

    const Eigen::AlignedBox3d box(Eigen::Vector3d(-2.0, -5.0, -1.0),
                                  Eigen::Vector3d(9.0, 3.0, 1.0));
    std::vector<Eigen::Vector3d> whole =
        registration::OccupiedPoints(small.LoadMap(small.Latest()), box);
    std::sort(whole.begin(), whole.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
        return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
    });
    ASSERT_GT(whole.size(), 1000u);
    EXPECT_TRUE(registration::OccupiedPointsByTiles(small, small.Latest(), box) == whole);
    EXPECT_TRUE(registration::OccupiedPointsByTiles(large, large.Latest(), box) == whole);

    // Aligned alike bit for bit.
    const AlignmentCase c = RoomAlignment();
    const MapAlignment a = AlignToMap(small, small.Latest(), c.cloud, c.guess, c.options);
    const MapAlignment b = AlignToMap(large, large.Latest(), c.cloud, c.guess, c.options);
    EXPECT_GT(a.result.iterations, 1);
    EXPECT_EQ(a.result.converged, b.result.converged);
    EXPECT_EQ(a.result.iterations, b.result.iterations);
    EXPECT_EQ(a.map_points, b.map_points);
    EXPECT_TRUE(a.result.T_map_source.matrix() == b.result.T_map_source.matrix());
}

}  // namespace
}  // namespace strata::pipeline
