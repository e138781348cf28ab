#include "SimulatedDrive.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

#include "TempPath.hpp"
#include "strata/sim/SimulateScene.hpp"

namespace strata::test {

size_t SimulatedDrive::Straight() const {
    size_t k = 1;
    while (k < truth.size() &&
           Eigen::AngleAxisd((truth[k - 1].inverse() * truth[k]).linear()).angle() < 0.1) {
        ++k;
    }
    return k;
}

const SimulatedDrive& DistrictDrive(size_t max_scans) {
    static std::map<size_t, SimulatedDrive> drives;
    auto [it, fresh] = drives.try_emplace(max_scans);
    if (!fresh) return it->second;
    namespace fs = std::filesystem;
    const fs::path source = fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/district_small.json";
    std::ifstream in(source);
    std::stringstream text;
    text << in.rdbuf();
    std::string json = text.str();
    const std::string every = "\"every\": 10";
    const size_t at = json.find(every);
    if (at == std::string::npos) throw std::runtime_error(source.string() + ": no \"every\": 10");
    json.replace(at, every.size(), "\"every\": 1");
    const fs::path scene = TempPath("district_every_metre.json");
    std::ofstream(scene) << json;
    sim::SimulateConfig config;
    config.max_scans = static_cast<int>(max_scans);
    const sim::SessionSimulation session(sim::LoadSceneSpec(scene), 0, config);
    SimulatedDrive& d = it->second;
    for (size_t k = 0; k < session.size(); ++k) {
        d.sweeps.push_back(session.Sweep(k).scan.points);
        d.truth.push_back(session.T_session_sensor(k));
    }
    return d;
}

}  // namespace strata::test
