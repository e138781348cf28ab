// Vehicles tile by tile. A vehicle is found by the window whose core holds its own first voxel;
// windows reach far enough around their core (a vehicle's columns, the ray checks' range, the
// ground's hole filling) that everything the core's vehicles and voxels depend on is what the
// whole map has there, but for objects longer than a window is sure to see whole (a hedge, a row
// of touching cars): their voxels are joined over the windows on rank 0, fitted there, and the
// blocks their vehicles reach are cleared again with them. The ground's regions are not local
// either (a street's ground is one region across the map), so a first pass over every tile joins
// them (vehicles::GroundRegions).
#include "VehiclesByTiles.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "TileBudget.hpp"
#include "VehiclesExchange.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/GridBox.hpp"
#include "strata/core/Labels.hpp"
#include "strata/pipeline/RankedSession.hpp"
#include "strata/store/TileReader.hpp"
#include "strata/vehicles/GroundRegions.hpp"
#include "strata/vehicles/VehicleStages.hpp"

namespace strata::pipeline::detail {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using store::TileKey;

int FloorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

bool HasVehicleLabel(const core::VoxelMap& tile) {
    const int32_t vehicle = static_cast<int32_t>(core::SemanticClass::kVehicle);
    for (auto it = tile.label->cbeginValueOn(); it; ++it) {
        if (*it == vehicle) return true;
    }
    return false;
}

// Square blocks of `side` x `side` tiles, each read with the tiles within `halo` voxels of it;
// the blocks cover the map's tiles and those within `edits` voxels of them (a vehicle at the
// map's edge refills ground where no tile was stored yet).
class Blocks {
public:
    Blocks(const store::Snapshot& snapshot, const store::MapSettings& settings, int halo, int edits,
           double memory_per_file_byte)
        : settings_(settings), halo_tiles_(HaloTiles(halo)), edit_tiles_(HaloTiles(edits)) {
        for (const store::TileVersion& t : snapshot.tiles) {
            bytes_[t.key] = static_cast<uint64_t>(
                std::ceil(static_cast<double>(t.bytes) * memory_per_file_byte));
        }
    }

    // The largest side whose every block's window fits the budget (0: no limit), at most so
    // large that each of `ranks` gets a block.
    [[nodiscard]] int Side(size_t budget, int ranks, const std::string& dir) {
        int side = 1;
        const uint64_t one = Largest(1);
        if (budget > 0 && one > budget) {
            throw RefusedError(dir + ": a tile with its halo of " + std::to_string(halo_tiles_) +
                               " tiles takes about " + Megabytes(static_cast<double>(one)) +
                               " in memory, more than the memory budget of " +
                               Megabytes(static_cast<double>(budget)) + "; raise --memory-budget");
        }
        for (int next = 2; next <= 64; ++next) {
            if (budget > 0 && Largest(next) > budget) break;
            if (Of(next).size() < static_cast<size_t>(ranks)) break;
            side = next;
        }
        side_ = side;
        return side;
    }
    // The blocks holding a tile or a tile the vehicles may edit, by their index.
    [[nodiscard]] std::vector<std::pair<int, int>> Of(int side) const {
        std::set<std::pair<int, int>> blocks;
        for (const auto& [key, bytes] : bytes_) {
            for (int dx = -edit_tiles_; dx <= edit_tiles_; ++dx) {
                for (int dy = -edit_tiles_; dy <= edit_tiles_; ++dy) {
                    blocks.insert({FloorDiv(key.x + dx, side), FloorDiv(key.y + dy, side)});
                }
            }
        }
        return {blocks.begin(), blocks.end()};
    }
    [[nodiscard]] CoordBBox Core(const std::pair<int, int>& b) const {
        const TileKey lo{b.first * side_, b.second * side_};
        const TileKey hi{lo.x + side_ - 1, lo.y + side_ - 1};
        return {settings_.TileBounds(lo).min(), settings_.TileBounds(hi).max()};
    }
    // The tiles of a block's window (present or not) and its columns.
    [[nodiscard]] std::vector<TileKey> Window(const std::pair<int, int>& b, int side,
                                              int halo_tiles = -1) const {
        const int h = halo_tiles < 0 ? halo_tiles_ : halo_tiles;
        std::vector<TileKey> keys;
        for (int x = b.first * side - h; x < (b.first + 1) * side + h; ++x) {
            for (int y = b.second * side - h; y < (b.second + 1) * side + h; ++y) {
                keys.push_back({x, y});
            }
        }
        return keys;
    }
    [[nodiscard]] bool Present(const TileKey& k) const { return bytes_.count(k) > 0; }
    [[nodiscard]] int HaloTiles(int halo_voxels) const {
        return (halo_voxels + settings_.tile_voxels - 1) / settings_.tile_voxels;
    }
    // Memory of a window's tiles.
    [[nodiscard]] uint64_t Cost(const std::vector<TileKey>& window) const {
        uint64_t sum = 0;
        for (const TileKey& k : window) {
            const auto it = bytes_.find(k);
            if (it != bytes_.end()) sum += it->second;
        }
        return sum;
    }

private:
    [[nodiscard]] uint64_t Largest(int side) const {
        uint64_t largest = 0;
        for (const auto& b : Of(side)) largest = std::max(largest, Cost(Window(b, side)));
        return largest;
    }
    const store::MapSettings& settings_;
    int halo_tiles_;
    int edit_tiles_;
    int side_ = 1;
    std::map<TileKey, uint64_t> bytes_;
};

// Pass 1: the ground's regions over every tile, and the source `auto` resolves to.
vehicles::GroundRegions JoinGround(const store::TileReader& reader,
                                   const store::MapSettings& settings,
                                   const std::vector<TileKey>& keys,
                                   const vehicles::VehicleConfig& config,
                                   vehicles::VehicleSource& source) {
    vehicles::GroundConfig labelled = config.ground, geometric = config.ground;
    labelled.use_labels = true;
    geometric.use_labels = false;
    std::optional<vehicles::GroundRegions> by_labels, by_geometry;
    if (source != vehicles::VehicleSource::kGeometric)
        by_labels.emplace(labelled, settings.voxel_size_m);
    if (source != vehicles::VehicleSource::kLabel)
        by_geometry.emplace(geometric, settings.voxel_size_m);
    bool vehicle_label = false;
    for (const TileKey& key : keys) {
        const auto tile = reader.Fused(key);
        if (!tile) continue;
        const CoordBBox box = settings.TileBounds(key);
        if (by_labels) by_labels->AddTile(*tile, box);
        if (by_geometry) by_geometry->AddTile(*tile, box);
        if (source == vehicles::VehicleSource::kAuto && !vehicle_label) {
            vehicle_label = HasVehicleLabel(*tile);
        }
    }
    if (source == vehicles::VehicleSource::kAuto) {
        source =
            vehicle_label ? vehicles::VehicleSource::kLabel : vehicles::VehicleSource::kGeometric;
    }
    vehicles::GroundRegions& chosen =
        source == vehicles::VehicleSource::kLabel ? *by_labels : *by_geometry;
    chosen.Join();
    return std::move(chosen);
}

// The window's ground field: the measured heights of its tiles, filled within the map's raster.
vehicles::GroundField WindowGround(const vehicles::GroundRegions& regions,
                                   const core::VoxelMap& window, const CoordBBox& columns,
                                   double voxel_size, const vehicles::GroundConfig& config,
                                   size_t& measured_in_core, const CoordBBox& core) {
    const std::vector<float> z = regions.Measured(window, columns);
    const CoordBBox& bounds = regions.bounds();
    const int i0 = std::max(columns.min().x(), bounds.min().x());
    const int j0 = std::max(columns.min().y(), bounds.min().y());
    const int i1 = std::min(columns.max().x(), bounds.max().x());
    const int j1 = std::min(columns.max().y(), bounds.max().y());
    if (i1 < i0 || j1 < j0) return {};
    const int width = columns.max().x() - columns.min().x() + 1;
    std::vector<float> clipped;
    clipped.reserve(static_cast<size_t>(i1 - i0 + 1) * static_cast<size_t>(j1 - j0 + 1));
    for (int j = j0; j <= j1; ++j) {
        for (int i = i0; i <= i1; ++i) {
            const float value = z[static_cast<size_t>(j - columns.min().y()) * width +
                                  static_cast<size_t>(i - columns.min().x())];
            clipped.push_back(value);
            const bool in_core = i >= core.min().x() && i <= core.max().x() &&
                                 j >= core.min().y() && j <= core.max().y();
            if (in_core && !std::isnan(value)) ++measured_in_core;
        }
    }
    return vehicles::GroundField::FromMeasured(CoordBBox(Coord(i0, j0, 0), Coord(i1, j1, 0)),
                                               std::move(clipped), voxel_size, config);
}

// One window: its tiles read, its ground field, its vehicles (the first pass without the long
// objects' vehicles, the second with them); the first pass counts the measured ground columns of
// its core into `result`.
vehicles::WindowVehicles ClearWindow(
    const store::TileReader& reader, const Blocks& blocks, const store::MapSettings& settings,
    const vehicles::GroundRegions& regions, const std::vector<TileKey>& keys,
    const vehicles::Window& bounds, const std::vector<Eigen::Vector3d>& origins,
    vehicles::VehicleResult& result, const vehicles::GroundConfig& ground_config,
    const vehicles::VehicleConfig& config, const vehicles::LongObjects* long_objects) {
    std::vector<TileKey> present;
    CoordBBox columns;
    for (const TileKey& k : keys) {
        columns.expand(settings.TileBounds(k));
        if (blocks.Present(k)) present.push_back(k);
    }
    core::VoxelMap window = reader.LoadFused(present);
    size_t measured = 0;
    const vehicles::GroundField ground = WindowGround(
        regions, window, columns, settings.voxel_size_m, ground_config, measured, bounds.core);
    vehicles::WindowVehicles found = vehicles::ClearVehiclesInWindow(
        window, ground, origins, bounds, result.source, config, long_objects);
    if (long_objects == nullptr) result.ground_columns += measured;
    return found;
}

// The long objects of every rank's windows joined and fitted on rank 0; every rank gets them.
vehicles::LongObjects JoinLongObjects(const Ranks& ranks,
                                      std::vector<vehicles::ObjectSample> samples,
                                      double voxel_size, vehicles::VehicleSource source,
                                      const std::vector<Eigen::Vector3d>& origins,
                                      const vehicles::VehicleConfig& config, size_t& voxels) {
    if (ranks.size() > 1) {
        const std::vector<std::string> all = ranks.Gather(EncodeSamples(samples));
        for (size_t r = 1; r < all.size(); ++r) {
            std::vector<vehicles::ObjectSample> theirs = DecodeSamples(all[r]);
            samples.insert(samples.end(), theirs.begin(), theirs.end());
        }
    }
    vehicles::LongObjects long_objects;
    OnEveryRank(ranks, [&] {
        if (!ranks.root()) return;
        voxels = samples.size();
        long_objects =
            vehicles::FitLongObjects(std::move(samples), voxel_size, source, origins, config);
    });
    if (ranks.size() == 1) return long_objects;
    return DecodeLongObjects(ranks.Broadcast(ranks.root() ? EncodeLongObjects(long_objects) : ""));
}

}  // namespace

VehiclesOutcome ClearVehiclesByTiles(const store::MapStore& map, const store::Snapshot& snapshot,
                                     const vehicles::VehicleConfig& config,
                                     size_t memory_budget_bytes, double memory_per_file_byte,
                                     const Ranks& ranks) {
    const auto start = std::chrono::steady_clock::now();
    const store::MapSettings& settings = map.settings();
    const double s = settings.voxel_size_m;
    const int halo = vehicles::WindowHaloVoxels(s, config);
    const store::TileReader reader(map, snapshot, 0);
    std::vector<TileKey> keys;
    for (const store::TileVersion& t : snapshot.tiles) keys.push_back(t.key);
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());

    VehiclesOutcome outcome;
    outcome.commit = snapshot.commit;
    outcome.config = config;
    vehicles::VehicleResult& result = outcome.result;
    result.source = config.source;
    const vehicles::GroundRegions regions =
        JoinGround(reader, settings, keys, config, result.source);
    vehicles::GroundConfig ground_config = config.ground;
    ground_config.use_labels = result.source == vehicles::VehicleSource::kLabel;

    Blocks blocks(snapshot, settings, halo, vehicles::EditReachVoxels(s, config),
                  memory_per_file_byte);
    const int side = blocks.Side(memory_budget_bytes, ranks.size(), map.dir().string());
    const std::vector<std::pair<int, int>> all_blocks = blocks.Of(side);
    std::vector<std::pair<int, int>> mine;
    for (size_t b = static_cast<size_t>(ranks.rank()); b < all_blocks.size();
         b += static_cast<size_t>(ranks.size())) {
        mine.push_back(all_blocks[b]);
    }
    const std::vector<Eigen::Vector3d> origins = SensorOrigins(map, snapshot);
    const auto window_of = [&](const std::pair<int, int>& b) {
        return vehicles::WindowAround(blocks.Core(b), s, config);
    };
    // First pass: every block, its long objects' voxels kept and their samples taken.
    std::vector<vehicles::WindowVehicles> found;
    std::vector<vehicles::ObjectSample> long_samples;
    OnEveryRank(ranks, [&] {
        for (const std::pair<int, int>& b : mine) {
            found.push_back(ClearWindow(reader, blocks, settings, regions, blocks.Window(b, side),
                                        window_of(b), origins, result, ground_config, config,
                                        nullptr));
            std::vector<vehicles::ObjectSample>& samples = found.back().long_samples;
            long_samples.insert(long_samples.end(), samples.begin(), samples.end());
            samples = {};
        }
    });
    outcome.tile_groups = all_blocks.size();
    // The long objects joined; the blocks their vehicles reach are cleared again with them.
    const vehicles::LongObjects long_objects = JoinLongObjects(
        ranks, std::move(long_samples), s, result.source, origins, config, outcome.long_voxels);
    outcome.long_objects = long_objects.objects;
    // Those blocks are dealt out afresh (every rank knows which they are), so that the second
    // pass shares its work as the first did; a block's first answer is dropped where it is
    // cleared again.
    const auto reached = [&](const std::pair<int, int>& b) {
        return vehicles::LongVehiclesReach(long_objects, window_of(b), s, config);
    };
    std::vector<std::pair<int, int>> again;
    std::copy_if(all_blocks.begin(), all_blocks.end(), std::back_inserter(again), reached);
    outcome.repeated_groups = again.size();
    std::vector<vehicles::WindowVehicles> kept;
    for (size_t i = 0; i < mine.size(); ++i) {
        if (!reached(mine[i])) kept.push_back(std::move(found[i]));
    }
    found = std::move(kept);
    OnEveryRank(ranks, [&] {
        for (size_t b = static_cast<size_t>(ranks.rank()); b < again.size();
             b += static_cast<size_t>(ranks.size())) {
            found.push_back(ClearWindow(reader, blocks, settings, regions,
                                        blocks.Window(again[b], side), window_of(again[b]), origins,
                                        result, ground_config, config, &long_objects));
        }
    });
    result.candidates += long_objects.objects;
    if (ranks.size() > 1) {
        const std::vector<std::string> all =
            ranks.Gather(ranks.root() ? "" : EncodeWindows(found, result.ground_columns));
        if (!ranks.root()) return outcome;
        for (size_t r = 1; r < all.size(); ++r) {
            for (vehicles::WindowVehicles& w : DecodeWindows(all[r], result.ground_columns)) {
                found.push_back(std::move(w));
            }
        }
    }
    // Ids in key order, as the whole map numbers its vehicles.
    std::vector<std::pair<vehicles::CarKey, vehicles::Vehicle>> cars;
    for (const vehicles::WindowVehicles& w : found) {
        cars.insert(cars.end(), w.vehicles.begin(), w.vehicles.end());
        result.candidates += w.candidates;
        result.occluder_faces += w.occluder_faces;
    }
    std::sort(cars.begin(), cars.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    std::map<vehicles::CarKey, int> ids;
    for (auto& [key, vehicle] : cars) {
        vehicle.id = static_cast<int>(ids.size()) + 1;
        ids[key] = vehicle.id;
        result.vehicles.push_back(vehicle);
    }
    std::tie(result.cleared, result.refilled) =
        vehicles::NewVehicleGrids(*core::VoxelMap::MakeTransform(s));
    auto cleared = result.cleared->getAccessor();
    auto refilled = result.refilled->getAccessor();
    for (const vehicles::WindowVehicles& w : found) {
        for (const auto& [c, key] : w.cleared) cleared.setValue(c, ids.at(key));
        for (const auto& [c, z] : w.refilled) refilled.setValue(c, z);
    }
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return outcome;
}

}  // namespace strata::pipeline::detail
