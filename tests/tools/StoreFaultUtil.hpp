#pragma once
// Shared by the fault-injection tests of the `strata` program (TestStoreFaults.cpp,
// TestStoreKills.cpp): the sessions they integrate, and how they compare maps.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "CliTestUtil.hpp"
#include "MapDiff.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::tools::test {

constexpr double kVoxelM = 0.1;
// 40 voxels: one scan touches ~12 tiles, so a commit writes ~12 files.
constexpr double kTileM = 4.0;
constexpr int kSequenceScans = 4;
constexpr unsigned kDefaultSeed = 20240611;  // STRATA_FAULT_SEED overrides it to reproduce a run
// Kills per run of the crash test; STRATA_KILL_ATTEMPTS raises it for long local runs
// (docs/reliability.md reports one of 120).
inline int KillAttempts() {
    const char* env = std::getenv("STRATA_KILL_ATTEMPTS");
    return env && *env ? std::max(1, std::atoi(env)) : 20;
}
// One scan (12k points in a 10 x 8 x 3 m room) per session: ~0.4 s per `strata integrate`, a
// good part of it the commit of ~12 fused files and ~12 layer files.
inline SequenceSpec FaultSequence() {
    SequenceSpec spec;
    spec.scans = kSequenceScans;
    spec.points_per_scan = 12000;
    spec.room_half_m = Eigen::Vector3d(5.0, 4.0, 1.5);
    return spec;
}

// Session `session` (1-based) integrates frame (session - 1) mod 4 of `seq`: the same session
// number always gets the same input, in any map.
inline std::vector<std::string> IntegrateArgs(const fs::path& map, const fs::path& seq, int session,
                                              double tile_m = kTileM) {
    return {"integrate",   map.string(),
            "--kitti",     seq.string(),
            "--frames",    std::to_string((session - 1) % kSequenceScans),
            "--voxel",     std::to_string(kVoxelM),
            "--tile-size", std::to_string(tile_m)};
}

inline std::string Join(const std::vector<std::string>& words) {
    std::string line;
    for (const std::string& w : words) line += (line.empty() ? "" : " ") + w;
    return line;
}

// The JSON object in a command's output (stderr lines, unbuffered, may come before it).
inline nlohmann::json JsonIn(const std::string& out) {
    const size_t begin = out.find('{');
    const size_t end = out.rfind('}');
    if (begin == std::string::npos || end == std::string::npos) return {};
    return nlohmann::json::parse(out.substr(begin, end - begin + 1), nullptr, false);
}

inline store::MapStore OpenForReading(const fs::path& map) {
    return store::MapStore::Open(map, store::MapStore::Access::kRead);
}

inline size_t SessionCount(const fs::path& map) {
    return OpenForReading(map).Latest().sessions.size();
}

inline core::VoxelMap LoadLatest(const fs::path& map) {
    const store::MapStore store = OpenForReading(map);
    return store.LoadMap(store.Latest());
}

// Exact equality of two maps, voxel by voxel: occupancy, label, label weight and hits.
inline ::testing::AssertionResult SameMap(const core::VoxelMap& actual,
                                          const core::VoxelMap& expected) {
    const std::string diff = strata::testing::MapDifference(actual, expected);
    if (!diff.empty()) return ::testing::AssertionFailure() << diff;
    return ::testing::AssertionSuccess();
}

inline unsigned Seed() {
    const char* env = std::getenv("STRATA_FAULT_SEED");
    return env && *env ? static_cast<unsigned>(std::stoul(env)) : kDefaultSeed;
}

}  // namespace strata::tools::test
