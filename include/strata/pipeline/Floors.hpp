#pragma once
// The storeys of a building map (`strata stack` records them, `strata localize` reads them):
// the rows of the map's newest `floors` commit (`SELECT * FROM floors`).

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "strata/store/MapStore.hpp"

namespace strata::pipeline {

/// @brief A storey: the session that mapped it in its own frame, where that frame sits in the
/// map, and the height of its floor surface.
struct FloorRecord {
    int index = 0;
    int64_t session = 0;
    double z_m = 0.0;  ///< floor surface height in the map frame
    Eigen::Matrix4d T_map_floor = Eigen::Matrix4d::Identity();  ///< session frame -> map frame
};

/// @brief The storeys recorded in `map`, by index; empty when none.
/// @throw FormatError naming the row when a row is damaged.
[[nodiscard]] std::vector<FloorRecord> ReadFloors(const store::MapStore& map);

/// @brief Stores every storey as one `floors` commit (the newest commit of a kind is what it
/// says); returns the commit.
int64_t WriteFloors(store::MapStore& map, const std::vector<FloorRecord>& floors);

/// @brief Where the storey's session saw occupied voxels, moved into the map frame.
[[nodiscard]] std::vector<Eigen::Vector3d> FloorPoints(const store::MapStore& map,
                                                       const store::Snapshot& snapshot,
                                                       const FloorRecord& floor);

}  // namespace strata::pipeline
