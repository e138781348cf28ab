#pragma once
// A coarse global search for the raw-point reference (RawIcp.hpp) where no pose is known: the
// structures above the sensor (walls, trunks, poles) seen from above, one point per cell, vote
// for every translation that maps a source point onto a target point, yaw by yaw; the best
// translations of the best yaws are the starts of the raw ICP. Shares no code with strata.

#include <Eigen/Geometry>
#include <vector>

namespace strata::registration::test {

struct CoarseSearchConfig {
    double min_z_m = 0.0;  ///< the band of heights (sensor frame) that votes
    double max_z_m = 3.0;
    double min_range_m = 3.0;  ///< range band of the voting points
    double max_range_m = 60.0;
    double point_cell_m = 2.0;  ///< one voting point per cell of this (from above)
    double vote_cell_m = 0.5;   ///< translation bins
    double max_shift_m = 40.0;  ///< translations searched within +- this in x and y
    double yaw_step_deg = 3.0;
};

struct CoarseCandidate {
    Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
    int votes = 0;
};

/// The best translation of every yaw, best first, at most `count`.
[[nodiscard]] std::vector<CoarseCandidate> CoarseSearch(const std::vector<Eigen::Vector3d>& target,
                                                        const std::vector<Eigen::Vector3d>& source,
                                                        size_t count,
                                                        const CoarseSearchConfig& config = {});

}  // namespace strata::registration::test
