#pragma once
// Shared by the store's tests: synthetic rooms whose in-memory integration is the known answer,
// maps built from them, and exact comparisons.

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "MapDiff.hpp"
#include "Sanitizer.hpp"
#include "TempPath.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/store/MapStore.hpp"
#include "strata/store/SessionWriter.hpp"

namespace strata::store::test {

namespace fs = std::filesystem;
using core::Scan;
using core::VoxelMap;
using integration::IntegrationConfig;

constexpr double kVoxel = 0.1;
constexpr double kTile = 3.2;  // 32 voxels: a 12 m room spans many tiles

/// The tile of the maps NewMap makes: kTile, or twice that under a sanitizer. Every grid of every
/// tile allocates OpenVDB's 264 KB top node, which the sanitizers' allocators map and fault in
/// afresh each time (docs/reliability.md, "Sanitizers"): the room over a quarter of the tiles
/// halves the store tests' time there and still spans several. Tests that count tiles or cut
/// regions at tile edges use NewMapOfManyTiles.
inline double TestTile() { return strata::testing::UnderSanitizer() ? 2 * kTile : kTile; }

inline fs::path Temp(const std::string& name) { return strata::test::TempPath("store_" + name); }

/// A 12 x 8 x 3 m room around `centre`, with labelled points (floor road, the rest building).
inline Scan RoomScan(uint32_t seed, const Eigen::Vector3d& centre, size_t n = 6000) {
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
        scan.labels.push_back(std::abs(d.z() * t + 1.5) < 1e-9 ? core::SemanticClass::kGround
                                                               : core::SemanticClass::kBuilding);
    }
    scan.source = "room_" + std::to_string(seed);
    scan.time_s = seed * 0.1;
    return scan;
}

inline std::vector<Scan> Session(uint32_t first_seed, const Eigen::Vector3d& start,
                                 size_t scans = 3) {
    std::vector<Scan> out;
    for (size_t k = 0; k < scans; ++k) {
        out.push_back(RoomScan(first_seed + static_cast<uint32_t>(k),
                               start + Eigen::Vector3d(0.7 * static_cast<double>(k), 0.3, 0.1)));
    }
    return out;
}

inline SessionOptions Named(const std::string& name) {
    SessionOptions options;
    options.name = name;
    return options;
}

inline MapStore NewMap(const fs::path& dir, const IntegrationConfig& rule = {},
                       double tile_m = TestTile()) {
    StoreSettings settings;
    settings.voxel_size_m = kVoxel;
    settings.tile_size_m = tile_m;
    settings.integration = rule;
    return MapStore::Create(dir, settings);
}

/// A map in kTile tiles in every build: for the tests that count tiles or cut regions at their
/// edges.
inline MapStore NewMapOfManyTiles(const fs::path& dir) { return NewMap(dir, {}, kTile); }

inline SessionRecord Write(MapStore& map, const std::vector<Scan>& scans,
                           SessionOptions options = {}, const IntegrationConfig& rule = {}) {
    SessionWriter writer(map, rule, std::move(options));
    for (const Scan& scan : scans) (void)writer.Integrate(scan);
    return writer.Commit();
}

/// The reference: the same scans integrated into one in-memory map.
inline VoxelMap InMemory(const std::vector<std::vector<Scan>>& sessions,
                         const IntegrationConfig& rule = {}) {
    VoxelMap map = VoxelMap::Create(kVoxel);
    integration::Integrator integrator(map, rule);
    for (const auto& scans : sessions) {
        for (const Scan& scan : scans) (void)integrator.Integrate(scan);
    }
    return map;
}

inline void ExpectSameMap(const VoxelMap& a, const VoxelMap& b) {
    EXPECT_EQ(testing::MapDifference(a, b), "");
}

/// True when `fn` throws an exception of kind `E` whose message holds `what`.
template <typename E = std::exception>
::testing::AssertionResult ThrowsNaming(const std::function<void()>& fn, const std::string& what) {
    try {
        fn();
    } catch (const std::exception& e) {
        if constexpr (!std::is_same_v<E, std::exception>) {
            if (dynamic_cast<const E*>(&e) == nullptr) {
                return ::testing::AssertionFailure() << "wrong kind of error: " << e.what();
            }
        }
        if (std::string(e.what()).find(what) != std::string::npos) {
            return ::testing::AssertionSuccess();
        }
        return ::testing::AssertionFailure()
               << "message '" << e.what() << "' lacks '" << what << "'";
    }
    return ::testing::AssertionFailure() << "no exception";
}

/// Bytes of the files of a list of file references.
template <typename Files>
uint64_t SumBytes(const Files& files) {
    uint64_t bytes = 0;
    for (const auto& f : files) bytes += f.bytes;
    return bytes;
}

}  // namespace strata::store::test
