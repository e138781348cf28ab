#include "MapTemplate.hpp"

#include <stdexcept>

#include "FuzzSupport.hpp"
#include "strata/core/Scan.hpp"
#include "strata/integration/IntegrationConfig.hpp"
#include "strata/store/MapStore.hpp"
#include "strata/store/SessionWriter.hpp"

namespace strata::fuzz {

std::string CreateSmallMap(const std::filesystem::path& dir) {
    store::StoreSettings settings;
    settings.voxel_size_m = 0.25;
    settings.tile_size_m = 8.0;  // one tile holds the whole scan: each input decodes little
    store::MapStore map = store::MapStore::Create(dir, settings);
    core::Scan scan;
    scan.source = "fuzz-template";
    scan.T_world_sensor.translation() = Eigen::Vector3d(1.5, 1.5, 0.5);  // inside tile (0, 0)
    // Two labelled walls 2 m and 3 m away, 1 m tall: a handful of occupied and free voxels.
    for (int i = -4; i <= 4; ++i) {
        for (int k = 0; k < 4; ++k) {
            scan.points.emplace_back(2.0, 0.25 * i, 0.25 * k);
            scan.labels.push_back(core::SemanticClass::kBuilding);
            scan.points.emplace_back(0.25 * i, 3.0, 0.25 * k);
            scan.labels.push_back(core::SemanticClass::kVehicle);
        }
    }
    store::SessionWriter writer(map, integration::IntegrationConfig{}, {});
    (void)writer.Integrate(scan);
    (void)writer.Commit();
    const store::Snapshot snapshot = map.Latest();
    if (snapshot.tiles.empty()) throw std::logic_error("fuzz template map has no tiles");
    return snapshot.tiles.front().file;
}

std::optional<store::CheckReport> ReadWholeMap(const std::filesystem::path& dir) {
    std::optional<store::CheckReport> report;
    Refusal([&] {
        const store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kRead);
        const store::Snapshot snapshot = map.Latest();
        for (const store::TileVersion& version : snapshot.tiles) {
            Refusal([&] { (void)map.ReadFused(version); });
        }
        for (const store::LayerFile& layer : snapshot.layers) {
            Refusal([&] { (void)map.ReadLayer(layer); });
        }
        Refusal([&] { (void)map.LoadMap(snapshot); });
        report = map.Check();
    });
    return report;
}

}  // namespace strata::fuzz
