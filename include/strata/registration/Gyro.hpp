#pragma once
// The sensor's rotation between two instants from an IMU's gyro: the odometry's prediction of a
// scan's rotation (docs/odometry.md, "Prediction").

#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <vector>

namespace strata::registration {

/// @brief Gyro readings: the angular velocity (rad/s) in the scans' sensor frame at instants
/// `times_s` (seconds, the scans' clock, increasing).
class Gyro {
public:
    /// @throw InvalidArgumentError when the sizes differ, an instant does not increase or a
    /// reading is not finite.
    Gyro(std::vector<double> times_s, std::vector<Eigen::Vector3d> rates_rad_s);

    /// @brief The sensor's rotation from instant `from` to instant `to` (its frame at `to` in its
    /// frame at `from`), the rates integrated between readings as the mean of the two around
    /// each interval; nullopt when the readings do not cover [from, to] or leave a gap longer
    /// than `max_gap_s` in it (a dropped topic says nothing about the turn it missed).
    [[nodiscard]] std::optional<Eigen::Matrix3d> Rotation(double from, double to,
                                                          double max_gap_s = 0.05) const;

    [[nodiscard]] size_t size() const { return times_s_.size(); }

private:
    std::vector<double> times_s_;
    std::vector<Eigen::Vector3d> rates_;
};

}  // namespace strata::registration
