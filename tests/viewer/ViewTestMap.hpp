#pragma once
// A small map whose content is known by construction, for the viewer's tests: a 12 x 8 x 3 m
// room scanned in session 1, the same room with a 1 m crate on its floor in session 2, a wall
// row with a slant grid over the room's north wall, and two saved change sets (one between the
// sessions, one against scans that were never committed).

#include <Eigen/Geometry>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "TempPath.hpp"
#include "strata/change/ChangeReport.hpp"
#include "strata/change/MapObserver.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/store/MapStore.hpp"
#include "strata/store/SessionWriter.hpp"

namespace strata::view::test {

namespace fs = std::filesystem;

inline constexpr double kVoxel = 0.1;
inline constexpr double kTile = 6.4;                     // 64 voxels: the room spans several tiles
inline const Eigen::Vector3d kCrateMin(2.0, 1.0, -1.5);  // the crate stands on the floor
inline constexpr double kCrateEdge = 1.0;
inline constexpr double kNorthWallY = 4.0;
inline constexpr float kNorthWallSlant = 88.0F;

/// Points on the room's faces (and the crate's, when `crate`), as a sensor at `at` sees them:
/// rays in uniform directions, each ending on the first face it meets.
inline core::Scan RoomScan(uint32_t seed, const Eigen::Vector3d& at, bool crate) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    core::Scan scan;
    scan.T_world_sensor.translation() = at;
    const Eigen::Array3d lo(-6.0, -4.0, -1.5), hi(6.0, 4.0, 1.5);
    const Eigen::Array3d crate_lo = kCrateMin.array(), crate_hi = crate_lo + kCrateEdge;
    for (int i = 0; i < 20000; ++i) {
        Eigen::Vector3d d;
        d.z() = u(rng);
        d.y() = u(rng);
        d.x() = u(rng);
        d.normalize();
        // The room: the nearest exit of the box along d.
        double t = 1e9;
        for (int a = 0; a < 3; ++a) {
            const double bound = d[a] > 0 ? hi[a] : lo[a];
            if (d[a] != 0) t = std::min(t, (bound - at[a]) / d[a]);
        }
        core::SemanticClass cls = core::SemanticClass::kBuilding;
        Eigen::Vector3d p = at + t * d;
        if (std::abs(p.z() - lo.z()) < 1e-9) cls = core::SemanticClass::kGround;
        if (crate) {  // slab test against the crate
            double t0 = 0, t1 = t;
            for (int a = 0; a < 3 && t0 <= t1; ++a) {
                const double inv = 1.0 / d[a];
                double ta = (crate_lo[a] - at[a]) * inv, tb = (crate_hi[a] - at[a]) * inv;
                if (ta > tb) std::swap(ta, tb);
                t0 = std::max(t0, ta);
                t1 = std::min(t1, tb);
            }
            if (t0 <= t1 && t0 > 0) {
                p = at + t0 * d;
                cls = core::SemanticClass::kOther;
            }
        }
        scan.points.push_back(p - at);
        scan.labels.push_back(cls);
    }
    scan.source = "room_" + std::to_string(seed);
    return scan;
}

struct TestMap {
    fs::path dir;
    int64_t walls_commit = 0;
};

inline void WriteSession(store::MapStore& map, bool crate, const std::string& name,
                         const Eigen::Vector3d& shift = Eigen::Vector3d::Zero()) {
    store::SessionOptions options;
    options.name = name;
    store::SessionWriter writer(map, integration::IntegrationConfig{}, options);
    for (uint32_t k = 0; k < 3; ++k) {
        const Eigen::Vector3d at = Eigen::Vector3d(-2.0 + 1.5 * k, -1.0, 0.0) + shift;
        (void)writer.Integrate(RoomScan(100 * (crate ? 2 : 1) + k, at, crate));
    }
    (void)writer.Commit();
}

/// Builds the map in a fresh scratch folder named after `name`.
inline TestMap BuildTestMap(const std::string& name) {
    TestMap out{strata::test::TempPath("view_" + name), 0};
    store::StoreSettings settings;
    settings.voxel_size_m = kVoxel;
    settings.tile_size_m = kTile;
    store::MapStore map = store::MapStore::Create(out.dir, settings);
    WriteSession(map, false, "empty room");
    WriteSession(map, true, "with crate");

    // The north wall's voxels as a wall product, with its catalog row.
    const core::VoxelMap fused = map.LoadMap(map.Latest());
    auto slant = openvdb::FloatGrid::create(0.0F);
    auto id = openvdb::Int32Grid::create(0);
    for (auto& grid : {openvdb::GridBase::Ptr(slant), openvdb::GridBase::Ptr(id)}) {
        grid->setTransform(fused.occupancy->transform().copy());
    }
    slant->setName("slant_deg");
    id->setName("wall_id");
    const int32_t j_wall = static_cast<int32_t>(std::floor(kNorthWallY / kVoxel));
    for (auto v = fused.occupancy->cbeginValueOn(); v; ++v) {
        if (*v > 0 && v.getCoord().y() >= j_wall - 1) {
            slant->tree().setValue(v.getCoord(), kNorthWallSlant);
            id->tree().setValue(v.getCoord(), 1);
        }
    }
    store::ProductCommit walls;  // as `strata walls` stores them (src/pipeline/Walls.cpp)
    walls.kind = "walls";
    walls.grids = {slant, id};
    walls.rows.push_back(nlohmann::json{
        {"wall_id", 1},
        {"center_x", 0.0},
        {"center_y", kNorthWallY},
        {"center_z", 0.0},
        {"normal_x", 0.0},
        {"normal_y", -1.0},
        {"normal_z", 0.0},
        {"slant_deg", kNorthWallSlant},
        {"length_m", 12.0},
        {"height_m", 3.0}}.dump());
    out.walls_commit = map.CommitProduct(walls);

    // A change set between the sessions, as `strata diff --from 1 --to 2 --save` keeps it.
    change::MapObserver observer(map);
    const change::ChangeQuery query;
    const change::ChangeSet changes =
        change::DetectChanges(observer.Session(1), observer.Session(2), kVoxel, query);
    // As pipeline::SaveChangeSet (src/pipeline/Diff.cpp) stores it.
    const auto save = [&](const std::string& from, const std::string& to) {
        store::ProductCommit set;
        set.kind = "change_sets";
        set.rows.push_back(
            nlohmann::json{{"from_side", from},
                           {"to_side", to},
                           {"added_voxels", changes.added_voxels_total},
                           {"removed_voxels", changes.removed_voxels_total},
                           {"unknown_voxels", changes.unknown_voxels},
                           {"objects", changes.objects.size()},
                           {"report", nlohmann::json::parse(change::ChangeReportJson(
                                          changes, {from, to, Eigen::Vector3d::Zero(), &query}))}}
                .dump());
        (void)map.CommitProduct(set);
    };
    save("session 1", "session 2");
    // One whose "after" side was scans never committed: its voxels cannot be rebuilt.
    save("session 1", "scans new_drive/ (3, uncommitted)");
    return out;
}

}  // namespace strata::view::test
