#include "SimulatedDrive.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>

#include "TempPath.hpp"
#include "strata/sim/GroundTruth.hpp"
#include "strata/sim/SimulateScene.hpp"

namespace strata::test {
namespace {

double Yaw(const Eigen::Isometry3d& T) {
    const Eigen::Vector3d forward = T.linear().col(0);
    return std::atan2(forward.y(), forward.x());
}

}  // namespace

size_t SimulatedDrive::Straight() const {
    const double limit = 5.0 * M_PI / 180.0;
    size_t k = 1;
    while (k < truth.size() &&
           std::abs(std::remainder(Yaw(truth[k]) - Yaw(truth.front()), 2.0 * M_PI)) < limit) {
        ++k;
    }
    return k;
}

double SimulatedDrive::Length() const {
    double length = 0.0;
    for (size_t k = 1; k < truth.size(); ++k) {
        length += (truth[k].translation() - truth[k - 1].translation()).norm();
    }
    return length;
}

const SimulatedDrive& DistrictDrive(size_t max_scans, const DriveShape& shape) {
    static std::map<std::tuple<size_t, double, double, bool>, SimulatedDrive> drives;
    auto [it, fresh] =
        drives.try_emplace({max_scans, shape.corner_m, shape.sway_deg, shape.motion});
    if (!fresh) return it->second;
    namespace fs = std::filesystem;
    const fs::path source = fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/district_small.json";
    nlohmann::json scene = nlohmann::json::parse(std::ifstream(source));
    nlohmann::json& drive = scene.at("district").at("drive");
    drive["every"] = 1;
    drive["corner"] = shape.corner_m;
    drive["sway_deg"] = shape.sway_deg;
    const fs::path file =
        TempPath("district_every_metre_" + std::to_string(max_scans) + "_" +
                 std::to_string(shape.corner_m) + "_" + std::to_string(shape.sway_deg) + ".json");
    std::ofstream(file) << scene.dump(1);
    sim::SimulateConfig config;
    config.max_scans = static_cast<int>(max_scans);
    config.motion = shape.motion;
    sim::SessionSimulation session(sim::LoadSceneSpec(file), 0, config);
    SimulatedDrive& d = it->second;
    d.ground_truth = file.parent_path() / (file.stem().string() + "_ground_truth.json");
    sim::WriteGroundTruth(d.ground_truth, session.scene().truth);
    for (size_t k = 0; k < session.size(); ++k) {
        sim::SimulatedScan sweep = session.Sweep(k);
        if (shape.motion) {
            std::vector<float>& times = d.times.emplace_back();
            for (const auto column : sweep.column) {
                times.push_back(static_cast<float>(session.sensor().ColumnTimeS(column)));
            }
        }
        d.sweeps.push_back(std::move(sweep.scan.points));
        d.truth.push_back(session.T_session_sensor(k));
        d.stamps.push_back(session.poses()[k].time_s);
    }
    return d;
}

}  // namespace strata::test
