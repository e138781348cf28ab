#pragma once
// Shared by the exporter tests: a small labelled map built by hand and a scratch directory.

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <string>

#include "strata/core/Labels.hpp"
#include "strata/core/VoxelMap.hpp"

namespace strata::io::export_test {

namespace fs = std::filesystem;
using core::SemanticClass;

inline constexpr double kVoxelSize = 0.2;
inline constexpr float kFloorLogOdds = 2.0f;
inline constexpr float kFreeLogOdds = -1.2f;
inline constexpr float kCarLogOdds = 3.0f;
// Floor z = 0 over x in [-10, 9], y in [-6, 5], with free air (z 1..3) above it.
inline const openvdb::CoordBBox kFloor({-10, -6, 0}, {9, 5, 0});
inline const openvdb::CoordBBox kCar({2, -1, 1}, {5, 1, 3});  // a vehicle-labelled block
inline const openvdb::Coord kPoleTop(-8, 3, 10);    // a building column x=-8, y=3, z 1..10
inline const openvdb::Coord kHole(-5, -5, 0);       // a column never observed
inline const openvdb::Coord kFreeColumn(-5, 4, 0);  // observed, all free
inline const openvdb::Coord kZeroVoxel(0, 0, 4);    // log-odds exactly 0: free
// Uniform regions stored as active tiles (8^3, leaf aligned), as a pruned map stores them.
inline const openvdb::CoordBBox kFreeTile({16, 16, 0}, {23, 23, 7});
inline const openvdb::CoordBBox kBuildingTile({24, 16, 0}, {31, 23, 7});

inline void Put(core::VoxelMap& map, const openvdb::Coord& ijk, float log_odds, SemanticClass c) {
    map.occupancy->tree().setValueOn(ijk, log_odds);
    if (log_odds > 0.0f) {
        map.label->tree().setValueOn(ijk, static_cast<int32_t>(c));
        map.label_weight->tree().setValueOn(ijk, 1.5f);
        map.SetEndpoints(ijk, 3, Eigen::Vector3d(0.01, -0.02, 0.0));
    }
}

inline core::VoxelMap MakeExportTestMap(const Eigen::Vector3d& origin = Eigen::Vector3d::Zero()) {
    core::VoxelMap map = core::VoxelMap::Create(kVoxelSize, origin);
    for (auto it = kFloor.begin(); it; ++it) {
        const openvdb::Coord ijk = *it;
        if (ijk.x() == kHole.x() && ijk.y() == kHole.y()) continue;
        const bool free_column = ijk.x() == kFreeColumn.x() && ijk.y() == kFreeColumn.y();
        Put(map, ijk, free_column ? kFreeLogOdds : kFloorLogOdds, SemanticClass::kGround);
        for (int z = 1; z <= 3; ++z) Put(map, ijk.offsetBy(0, 0, z), kFreeLogOdds, {});
    }
    for (auto it = kCar.begin(); it; ++it) Put(map, *it, kCarLogOdds, SemanticClass::kVehicle);
    for (int z = 1; z <= kPoleTop.z(); ++z) {
        Put(map, {kPoleTop.x(), kPoleTop.y(), z}, 0.5f + 0.25f * z, SemanticClass::kBuilding);
    }
    Put(map, kZeroVoxel, 0.0f, {});
    map.occupancy->tree().fill(kFreeTile, -2.0f, true);
    map.occupancy->tree().fill(kBuildingTile, 1.0f, true);
    map.label->tree().fill(kBuildingTile, static_cast<int32_t>(SemanticClass::kBuilding), true);
    return map;
}

/// A fresh directory under the system temp directory, removed with everything in it.
class ScratchDir {
public:
    explicit ScratchDir(const std::string& name) {
        static std::atomic<int> counter{0};
        path_ = fs::temp_directory_path() /
                ("strata_export_" + name + "_" + std::to_string(::getpid()) + "_" +
                 std::to_string(counter++));
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~ScratchDir() {
        std::error_code ignored;
        fs::remove_all(path_, ignored);
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
    [[nodiscard]] const fs::path& path() const { return path_; }
    [[nodiscard]] fs::path operator/(const std::string& name) const { return path_ / name; }
    /// Number of entries in the directory (to check that no temporary file was left behind).
    [[nodiscard]] int EntryCount() const {
        int n = 0;
        for ([[maybe_unused]] const auto& e : fs::directory_iterator(path_)) ++n;
        return n;
    }

private:
    fs::path path_;
};

/// Runs `write`, which must throw std::runtime_error whose message names `path`.
template <typename WriteFn>
void ExpectErrorNaming(const fs::path& path, WriteFn&& write) {
    try {
        write();
        ADD_FAILURE() << "expected std::runtime_error for " << path;
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
}

}  // namespace strata::io::export_test
