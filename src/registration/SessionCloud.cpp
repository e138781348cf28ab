#include "strata/registration/SessionCloud.hpp"

#include <algorithm>
#include <cmath>

#include "strata/core/Error.hpp"

namespace strata::registration {

void SessionCloudConfig::Validate() const {
    if (!(cell_m > 0.0)) throw InvalidArgumentError("session cloud: cell_m must be > 0");
    if (!(min_range_m >= 0.0) || !(max_range_m > min_range_m)) {
        throw InvalidArgumentError("session cloud: need 0 <= min_range_m < max_range_m");
    }
    if (max_points > (size_t{1} << 31)) {
        throw InvalidArgumentError("session cloud: max_points must be at most 2^31");
    }
}

namespace {

// A well-mixed 64-bit hash of a cell (SplitMix64's finaliser over its packed coordinates).
uint64_t Mix(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

uint64_t HashOf(const openvdb::Coord& c) {
    const auto u = [](int32_t v) { return static_cast<uint64_t>(static_cast<uint32_t>(v)); };
    return Mix(Mix(Mix(u(c.x())) ^ u(c.y())) ^ u(c.z()));
}

}  // namespace

CloudAccumulator::CloudAccumulator(const SessionCloudConfig& config) : config_(config) {
    config_.Validate();
}

void CloudAccumulator::Add(const core::Scan& scan) {
    const double inv_cell = 1.0 / config_.cell_m;
    const double min2 = config_.min_range_m * config_.min_range_m;
    const double max2 = config_.max_range_m * config_.max_range_m;
    for (const Eigen::Vector3d& p_sensor : scan.points) {
        const double r2 = p_sensor.squaredNorm();
        if (!std::isfinite(r2) || r2 < min2 || r2 > max2) continue;
        const Eigen::Vector3d p = scan.T_world_sensor * p_sensor;
        const openvdb::Coord c(static_cast<int32_t>(std::floor(p.x() * inv_cell)),
                               static_cast<int32_t>(std::floor(p.y() * inv_cell)),
                               static_cast<int32_t>(std::floor(p.z() * inv_cell)));
        // A cell at or above the bound is out for good (the bound only falls); below it, a
        // cell kept already keeps its first point.
        const uint64_t hash = HashOf(c);
        if (hash >= below_) continue;
        if (index_.Contains(c)) continue;
        index_.Set(c, static_cast<int32_t>(kept_.size()));
        kept_.push_back({p, hash, c});
        if (config_.max_points > 0 && kept_.size() > config_.max_points) {
            // Past the limit: halve the bound and drop the cells above it, keeping the order.
            while (kept_.size() > config_.max_points) {
                below_ /= 2;
                kept_.erase(std::remove_if(kept_.begin(), kept_.end(),
                                           [&](const Kept& k) { return k.hash >= below_; }),
                            kept_.end());
            }
            index_ = {};
            for (size_t k = 0; k < kept_.size(); ++k) {
                index_.Set(kept_[k].cell, static_cast<int32_t>(k));
            }
        }
    }
}

std::vector<Eigen::Vector3d> CloudAccumulator::TakePoints() {
    std::vector<Eigen::Vector3d> points;
    points.reserve(kept_.size());
    for (const Kept& k : kept_) points.push_back(k.point);
    std::vector<Kept>().swap(kept_);
    index_ = {};
    return points;
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
