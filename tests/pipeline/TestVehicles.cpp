// Vehicles of a stored map: cleared in memory, then stored as one `vehicles` commit that edits
// the fused map (the previous state stays readable).
#include <gtest/gtest.h>

#include "PipelineTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/pipeline/MapAccess.hpp"
#include "strata/pipeline/Vehicles.hpp"

namespace strata::pipeline::test {
namespace {

// Occupied voxels labelled vehicle.
size_t VehicleVoxels(const core::VoxelMap& map) {
    size_t n = 0;
    const auto label = map.label->getConstAccessor();
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it > 0.0f &&
            label.getValue(it.getCoord()) == static_cast<int32_t>(core::SemanticClass::kVehicle)) {
            ++n;
        }
    }
    return n;
}

// datasets/scenes/street.json, 4 scans with their labels, as one session.
fs::path Street() {
    const fs::path dir = Temp("street");
    ScanSpec scans;
    scans.kitti = Simulated("street", 4).report.sessions.at(0).dir;
    IntegrateOptions options;
    options.name = "drive";
    (void)IntegrateSession(dir, scans, options);
    return dir;
}

TEST(PipelineVehicles, ClearsTheParkedCarsAndStoresTheCleanedMapAsOneCommit) {
    const fs::path dir = Street();
    store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kWrite);
    const store::Snapshot before = map.Latest();
    const size_t labelled = VehicleVoxels(map.LoadMap(before));
    VehiclesOutcome outcome = ClearVehicles(map, before, vehicles::VehicleConfig{});
    ASSERT_GE(outcome.result.vehicles.size(), 3u);
    EXPECT_LT(VehicleVoxels(outcome.cleaned), labelled / 2);
    EXPECT_EQ(map.Latest().commit, before.commit) << "clearing alone writes nothing";

    const size_t vehicles = outcome.result.vehicles.size();
    const int64_t commit = StoreVehicles(map, outcome);
    EXPECT_EQ(map.Latest().commit, commit);
    const std::vector<store::ProductRow> rows = map.ProductRows("vehicles");
    ASSERT_EQ(rows.size(), vehicles);
    EXPECT_EQ(nlohmann::json::parse(rows[0].json),
              nlohmann::json::parse(VehicleRow(outcome.result.vehicles[0])));
    EXPECT_LT(VehicleVoxels(map.LoadMap(map.Latest())), labelled / 2) << "the map as stored";
    EXPECT_EQ(VehicleVoxels(map.LoadMap(SelectSnapshot(map, "drive"))), labelled)
        << "as of the session, the map is as scanned";
}

TEST(PipelineVehicles, StoringFromAReaderIsRefused) {
    const fs::path dir = Street();
    const MapState before = StateOf(dir, "vehicles");
    store::MapStore reader = store::MapStore::Open(dir, store::MapStore::Access::kRead);
    VehiclesOutcome outcome = ClearVehicles(reader, reader.Latest(), vehicles::VehicleConfig{});
    EXPECT_THROW((void)StoreVehicles(reader, outcome), InvalidArgumentError);
    EXPECT_EQ(StateOf(dir, "vehicles"), before);
}

}  // namespace
}  // namespace strata::pipeline::test
