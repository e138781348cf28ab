#include "strata/registration/SessionCloud.hpp"

#include <cmath>

#include "strata/core/Error.hpp"

namespace strata::registration {

void SessionCloudConfig::Validate() const {
    if (!(cell_m > 0.0)) throw InvalidArgumentError("session cloud: cell_m must be > 0");
    if (!(min_range_m >= 0.0) || !(max_range_m > min_range_m)) {
        throw InvalidArgumentError("session cloud: need 0 <= min_range_m < max_range_m");
    }
}

CloudAccumulator::CloudAccumulator(const SessionCloudConfig& config)
    : config_(config), seen_(openvdb::BoolGrid::create(false)) {
    config_.Validate();
}

void CloudAccumulator::Add(const core::Scan& scan) {
    const double inv_cell = 1.0 / config_.cell_m;
    const double min2 = config_.min_range_m * config_.min_range_m;
    const double max2 = config_.max_range_m * config_.max_range_m;
    auto acc = seen_->getAccessor();
    for (const Eigen::Vector3d& p_sensor : scan.points) {
        const double r2 = p_sensor.squaredNorm();
        if (!std::isfinite(r2) || r2 < min2 || r2 > max2) continue;
        const Eigen::Vector3d p = scan.T_world_sensor * p_sensor;
        const openvdb::Coord c(static_cast<int32_t>(std::floor(p.x() * inv_cell)),
                               static_cast<int32_t>(std::floor(p.y() * inv_cell)),
                               static_cast<int32_t>(std::floor(p.z() * inv_cell)));
        if (acc.isValueOn(c)) continue;
        acc.setValueOn(c, true);
        points_.push_back(p);
    }
}

std::vector<Eigen::Vector3d> SessionCloud(const std::vector<core::Scan>& scans,
                                          const SessionCloudConfig& config) {
    CloudAccumulator acc(config);
    for (const core::Scan& scan : scans) acc.Add(scan);
    return acc.TakePoints();
}

Eigen::AlignedBox3d RangeBox(const Eigen::Isometry3d& T_map_sensor, double range_m) {
    const Eigen::Vector3d half = Eigen::Vector3d::Constant(range_m);
    return Eigen::AlignedBox3d(T_map_sensor.translation() - half,
                               T_map_sensor.translation() + half);
}

}  // namespace strata::registration
