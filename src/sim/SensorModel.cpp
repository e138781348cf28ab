#include "strata/sim/SensorModel.hpp"

#include <cmath>
#include <stdexcept>

#include "strata/core/Error.hpp"

namespace strata::sim {
namespace {

std::vector<double> Uniform(double top_deg, double bottom_deg, int beams) {
    std::vector<double> table(static_cast<size_t>(beams));
    for (int i = 0; i < beams; ++i) {
        table[static_cast<size_t>(i)] = top_deg + (bottom_deg - top_deg) * i / (beams - 1);
    }
    return table;
}

// Velodyne HDL-64E S2 (the KITTI sensor). Source: HDL-64E S2 datasheet and manual: vertical
// field of view +2.0 to -24.8 deg in two blocks of 32 lasers, the upper block about 1/3 deg
// apart, the lower block about 1/2 deg apart; 10 Hz gives about 0.17 deg between firings
// (1.33 M points/s), range 120 m, accuracy < 2 cm. Checked against KITTI sequence 00 frame 0:
// its elevations span about +2 to -25 deg (per-laser offsets spread them a little).
SensorModel Hdl64() {
    SensorModel s;
    s.name = "hdl64";
    s.elevation_deg = Uniform(2.0, -8.0 - 1.0 / 3.0, 32);
    const std::vector<double> lower = Uniform(-8.83, -24.8, 32);
    s.elevation_deg.insert(s.elevation_deg.end(), lower.begin(), lower.end());
    s.columns = 2083;
    s.min_range_m = 0.9;
    s.max_range_m = 120.0;
    return s;
}

// Velodyne VLP-16. Source: VLP-16 user manual, laser table: -15 to +15 deg every 2 deg
// (firing order interleaved; listed here top to bottom), 0.2 deg azimuth at 10 Hz, 100 m.
SensorModel Vlp16() {
    SensorModel s;
    s.name = "vlp16";
    s.elevation_deg = Uniform(15.0, -15.0, 16);
    s.columns = 1800;
    s.min_range_m = 0.5;
    s.max_range_m = 100.0;
    return s;
}

// Ouster OS1 gen2. Source: OS1 gen2 datasheet: 45 deg vertical field of view (+22.5 to
// -22.5 deg) with uniform beam spacing, 1024 columns in 1024x10 mode, 120 m range.
SensorModel Os1(int beams) {
    SensorModel s;
    s.name = "os1-" + std::to_string(beams);
    s.elevation_deg = Uniform(22.5, -22.5, beams);
    s.columns = 1024;
    s.min_range_m = 0.3;
    s.max_range_m = 120.0;
    return s;
}

}  // namespace

SensorModel SensorModel::FromName(const std::string& name) {
    if (name == "hdl64") return Hdl64();
    if (name == "vlp16") return Vlp16();
    if (name == "os1-64") return Os1(64);
    if (name == "os1-128") return Os1(128);
    throw InvalidArgumentError("unknown sensor '" + name + "' (hdl64, vlp16, os1-64, os1-128)");
}

std::vector<std::string> SensorModel::Names() { return {"hdl64", "vlp16", "os1-64", "os1-128"}; }

double SensorModel::ColumnAzimuthRad(int column) const {
    return M_PI - 2.0 * M_PI * (column + 0.5) / columns;
}

double SensorModel::ColumnTimeS(int column) const { return (column + 0.5) / (columns * rate_hz); }

void SensorModel::Validate() const {
    const auto fail = [this](const std::string& what) {
        throw InvalidArgumentError("sensor '" + name + "': " + what);
    };
    if (elevation_deg.empty()) fail("empty beam table");
    for (double e : elevation_deg) {
        if (!(std::abs(e) < 90.0)) fail("elevations must be inside (-90, 90) deg");
    }
    if (columns < 1 || !(rate_hz > 0.0)) fail("columns >= 1 and rate_hz > 0 needed");
    if (!(min_range_m >= 0.0 && max_range_m > min_range_m)) fail("0 <= min_range < max_range");
    if (!(range_noise_m >= 0.0) || !(intensity_noise >= 0.0)) fail("noise must be >= 0");
    if (!(dropout_probability >= 0.0 && dropout_probability < 1.0)) fail("dropout in [0, 1)");
    if (!(grazing_cos >= 0.0 && grazing_cos < 1.0)) fail("grazing_cos in [0, 1)");
}

}  // namespace strata::sim
