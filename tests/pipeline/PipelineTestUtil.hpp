#pragma once
// Shared by the use-case tests: scratch paths, what a reader sees of a map (to prove a refusal
// changed nothing), the box room integrated, and simulated scenes with their true frames.

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "Sanitizer.hpp"
#include "SharedFixture.hpp"
#include "SyntheticRoom.hpp"
#include "TempPath.hpp"
#include "strata/pipeline/Integrate.hpp"
#include "strata/registration/Register.hpp"
#include "strata/sim/SimulateScene.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::pipeline::test {

namespace fs = std::filesystem;
using strata::test::MakeSequence;
using strata::test::MapFiles;
using strata::test::RoomScans;
using strata::test::SequenceSpec;

/// A scratch path unique to this process, removed first and at exit.
inline fs::path Temp(const std::string& name) { return strata::test::TempPath("pipeline_" + name); }

/// What a reader sees of a map: its tile files byte for byte, its newest commit and sessions,
/// the rows of a product kind. Equal before and after: nothing was changed.
struct MapState {
    std::map<std::string, std::string> files;
    int64_t commit = 0;
    size_t sessions = 0;
    size_t product_rows = 0;
    bool operator==(const MapState& o) const {
        return files == o.files && commit == o.commit && sessions == o.sessions &&
               product_rows == o.product_rows;
    }
};

inline MapState StateOf(const fs::path& dir, const std::string& kind = "walls") {
    const store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kRead);
    const store::Snapshot latest = map.Latest();
    return {MapFiles(dir), latest.commit, latest.sessions.size(), map.ProductRows(kind).size()};
}

/// The room of `spec` written as a KITTI sequence and integrated into `map` as one session.
inline IntegrateResult IntegrateRoom(const fs::path& map, const std::string& name,
                                     const SequenceSpec& spec = {}, IntegrateOptions options = {}) {
    ScanSpec scans;
    scans.kitti = MakeSequence(Temp(name + "_seq"), spec);
    if (!options.map.voxel_size_m) options.map.voxel_size_m = 0.1;
    options.name = name;
    return IntegrateSession(map, scans, options);
}

// A 16 x 12 x 5 m room, every scan of the same room (the sensor moves 0.4 m per scan).
inline SequenceSpec Hall() {
    SequenceSpec spec;
    spec.room_half_m = Eigen::Vector3d(8.0, 6.0, 2.5);
    spec.points_per_scan = 20000;
    spec.step_m = 0.4;
    return spec;
}

// The same hall recorded again, its poses given in a frame moved by (0.3, -0.2, 0.05), 2 deg.
inline SequenceSpec HallInAMovedFrame() {
    SequenceSpec spec = Hall();
    spec.seed = 11;
    spec.T_session_world = registration::PoseFromXyzYaw(0.3, -0.2, 0.05, 2.0).inverse();
    return spec;
}

// Room walls move with the sensor (SyntheticRoom.hpp): with step 0 the scans see one room.
inline SequenceSpec StillRoom(const SequenceSpec& base) {
    SequenceSpec spec = base;
    spec.step_m = 0.0;
    return spec;
}

inline AlignRequest CloseRangeAlignment() {
    AlignRequest align;
    align.options.min_range_m = 0.5;  // the hall is small: keep the near walls
    return align;
}

/// A scene of datasets/scenes simulated into KITTI sequences (every session at most
/// `max_scans` scans), once per process and scene; its spec holds the true session frames.
struct SimulatedScene {
    sim::SceneSpec spec;
    sim::SimulateReport report;
};

inline const SimulatedScene& Simulated(const std::string& scene, int max_scans) {
    static std::map<std::string, std::unique_ptr<SimulatedScene>> cache;
    const std::string key = scene + "_" + std::to_string(max_scans);
    std::unique_ptr<SimulatedScene>& s = cache[key];
    if (!s) {
        s = std::make_unique<SimulatedScene>();
        s->spec = sim::LoadSceneSpec(fs::path(STRATA_SOURCE_DIR) / "datasets" / "scenes" /
                                     (scene + ".json"));
        sim::SimulateConfig config;
        config.max_scans = max_scans;
        config.write_picture = false;
        s->report = sim::SimulateSceneToSequence(s->spec, Temp("sim_" + key), config);
    }
    return *s;
}

/// datasets/scenes/building.json simulated (`scans` per storey) and integrated at 0.1 m, storey
/// k as session "floor_k" in its own frame, into a fresh map in `dir`.
inline const SimulatedScene& BuildingMap(const fs::path& dir, int scans) {
    const SimulatedScene& building = Simulated("building", scans);
    for (size_t k = 0; k < building.report.sessions.size(); ++k) {
        ScanSpec storey;
        storey.kitti = building.report.sessions[k].dir;
        IntegrateOptions options;
        options.map.voxel_size_m = 0.1;
        options.name = "floor_" + std::to_string(k);
        (void)IntegrateSession(dir, storey, options);
    }
    return building;
}

/// Tile edge of StreetInSmallTiles: its facades and parked cars cross many tile borders. Under a
/// sanitizer 1.5 times that (less than half the tiles; 12.8 m would make a tile's halo exceed the
/// tests' budget): every tile read costs a sanitizer far more than it costs a release build
/// (docs/reliability.md, "Sanitizers").
inline double SmallTileM() { return strata::testing::UnderSanitizer() ? 9.6 : 6.4; }

/// datasets/scenes/street.json, 12 scans, integrated in SmallTileM() tiles, once per suite run
/// (strata::test::SharedFixture): the map the tile-by-tile analyses are compared with their
/// whole-map selves on (read only).
inline const fs::path& StreetInSmallTiles() {
    static const fs::path dir = strata::test::SharedFixture(
        "street_12_scans_in_tiles_of_" + std::to_string(SmallTileM()), [](const fs::path& d) {
            ScanSpec scans;
            scans.kitti = Simulated("street", 12).report.sessions.at(0).dir;
            IntegrateOptions options;
            options.map.tile_size_m = SmallTileM();
            (void)IntegrateSession(d, scans, options);
        });
    return dir;
}

}  // namespace strata::pipeline::test
