#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/core/Scan.hpp"
#include "strata/registration/Surface.hpp"

namespace strata::registration {

/// @brief How the scans of a session become one cloud to register.
struct SessionCloudConfig {
    double cell_m = 0.1;        ///< one point per cell (the first), metres
    double min_range_m = 1.0;   ///< the vehicle and the operator are not the map
    double max_range_m = 60.0;  ///< far returns are sparse and noisy
    /// At most this many points (0 = no limit). A session over more cells keeps the first point
    /// of each cell whose hash is below a bound, halved until at most `max_points` cells are
    /// left (about half to all of them): a uniform sample of its cells, the same whatever order the
    /// scans come in, in about 60 bytes a kept point. The alignment matches at most 20 000 of them
    /// (RegistrationConfig::max_finest_source_points).
    size_t max_points = 1'000'000;  ///< at most 2^31

    /// @brief Throws InvalidArgumentError naming the field when a value is out of range.
    void Validate() const;
};

/// @brief The points of many posed scans in their common (session) frame, thinned to one per
/// cell (the first to come) and to at most `max_points` cells, in the order they came. Scans
/// are added one at a time, so a long session need not be held in memory.
class CloudAccumulator {
public:
    /// @throw InvalidArgumentError on an invalid config.
    explicit CloudAccumulator(const SessionCloudConfig& config = {});
    /// @brief Adds `scan.points` moved by `scan.T_world_sensor`; non-finite points are skipped.
    void Add(const core::Scan& scan);
    [[nodiscard]] size_t size() const { return kept_.size(); }
    /// @brief The points in the order they came; the accumulator is left empty.
    [[nodiscard]] std::vector<Eigen::Vector3d> TakePoints();

private:
    struct Kept {
        Eigen::Vector3d point;
        uint64_t hash;  // of its cell
        openvdb::Coord cell;
    };
    SessionCloudConfig config_;
    uint64_t below_ = std::numeric_limits<uint64_t>::max();  // cells kept: hash below this
    std::vector<Kept> kept_;                                 // in the order they came
    CellTable index_;                                        // kept cell -> its index in kept_
};

/// @brief CloudAccumulator over all of `scans`.
[[nodiscard]] std::vector<Eigen::Vector3d> SessionCloud(const std::vector<core::Scan>& scans,
                                                        const SessionCloudConfig& config = {});

/// @brief The box of half-edge `range_m` around a sensor pose's position: the part of a map a
/// scan taken there can see.
[[nodiscard]] Eigen::AlignedBox3d RangeBox(const Eigen::Isometry3d& T_map_sensor, double range_m);

}  // namespace strata::registration
