#pragma once

#include <string>
#include <vector>

namespace strata::sim {

/// @brief A spinning multi-beam LiDAR: one column of beams fired at each of `columns` azimuths
/// per revolution. Sensor frame as KITTI's Velodyne: x forward, y left, z up.
/// @note Column c fires at azimuth pi - 2 pi (c + 0.5) / columns (the sweep starts behind the
/// sensor and turns clockwise seen from above) and at time (c + 0.5) / (columns * rate_hz)
/// after the start of the sweep.
struct SensorModel {
    std::string name;
    std::vector<double> elevation_deg;  ///< one per beam, from the table of the sensor
    int columns = 2083;                 ///< firings per revolution: 360 / columns deg apart
    double rate_hz = 10.0;              ///< revolutions per second
    double min_range_m = 0.9;           ///< returns closer than this are lost
    double max_range_m = 120.0;         ///< no return beyond this range
    double range_noise_m = 0.02;        ///< standard deviation of the Gaussian range noise
    double dropout_probability = 0.01;  ///< chance that any return is lost
    double grazing_cos = 0.03;          ///< returns with |cos(incidence)| below this are lost
    double intensity_noise = 0.02;      ///< standard deviation added to the intensity

    /// @brief Sensors by name: "hdl64" (Velodyne HDL-64E, KITTI), "vlp16" (Velodyne VLP-16),
    /// "os1-64" and "os1-128" (Ouster OS1 gen2). Throws InvalidArgumentError otherwise.
    [[nodiscard]] static SensorModel FromName(const std::string& name);
    /// @brief Names accepted by FromName.
    [[nodiscard]] static std::vector<std::string> Names();

    [[nodiscard]] size_t beams() const { return elevation_deg.size(); }
    [[nodiscard]] size_t rays_per_scan() const { return beams() * static_cast<size_t>(columns); }
    [[nodiscard]] double azimuth_resolution_deg() const { return 360.0 / columns; }
    /// @brief Azimuth of a column in radians (see the class note).
    [[nodiscard]] double ColumnAzimuthRad(int column) const;
    /// @brief Seconds from the start of the sweep to the firing of a column.
    [[nodiscard]] double ColumnTimeS(int column) const;
    /// @brief Throws InvalidArgumentError for an empty beam table or out-of-range values.
    void Validate() const;
};

}  // namespace strata::sim
