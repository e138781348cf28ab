#include "DemoScene.hpp"

#include "Progress.hpp"
#include "strata/sim/SimulateScene.hpp"

namespace strata::tools {

std::filesystem::path SimulateDemoStreet(const std::filesystem::path& dir) {
    std::filesystem::remove_all(dir);
    Progress progress("simulating", 0);
    sim::SimulateConfig config;
    const auto report = sim::SimulateSceneToSequence(
        sim::DemoStreetScene(), dir, config,
        [&](size_t done, size_t total) { progress.Update(done, total); });
    return report.sessions.front().dir;
}

}  // namespace strata::tools
