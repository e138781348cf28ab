// The simulator from Python, one scan at a time (strata.simulate is the generator around it).
// Each scan is what `strata simulate` would write for it (sim::SessionSimulation simulates both):
// float32 points in the sensor frame, SemanticKITTI labels, the pose in the session's frame; so
// a map integrated from these arrays equals `strata integrate` on the written sequence.
#include <pybind11/stl.h>

#include <memory>
#include <optional>

#include "Arrays.hpp"
#include "Bindings.hpp"
#include "strata/sim/SceneSpec.hpp"
#include "strata/sim/SimulateScene.hpp"

namespace strata::python {

namespace {

class Simulation {
public:
    Simulation(const std::string& scene, size_t session, const std::string& sensor,
               std::optional<uint64_t> seed, int max_scans) {
        py::gil_scoped_release release;
        spec_ = scene == "demo" ? sim::DemoStreetScene() : sim::LoadSceneSpec(scene);
        spec_.Validate();
        sim::SimulateConfig config;
        config.sensor = sensor;
        config.seed = seed;
        config.max_scans = max_scans;
        run_ = std::make_unique<sim::SessionSimulation>(spec_, session, config);
        session_ = session;
    }

    [[nodiscard]] size_t size() const { return run_->size(); }

    [[nodiscard]] py::dict Scan(size_t k) const {
        if (k >= run_->size()) {
            throw py::index_error("scan " + std::to_string(k) + " of " +
                                  std::to_string(run_->size()));
        }
        sim::SimulatedScan scan;
        {
            py::gil_scoped_release release;
            scan = run_->Sweep(k);
        }
        const auto n = static_cast<py::ssize_t>(scan.scan.points.size());
        std::vector<float> points(scan.scan.points.size() * 3);
        std::vector<uint8_t> classes(scan.scan.labels.size());
        for (size_t i = 0; i < scan.scan.points.size(); ++i) {
            for (int a = 0; a < 3; ++a) {
                points[3 * i + static_cast<size_t>(a)] = static_cast<float>(scan.scan.points[i][a]);
            }
        }
        for (size_t i = 0; i < classes.size(); ++i)
            classes[i] = static_cast<uint8_t>(scan.scan.labels[i]);
        py::dict out;
        out["points"] = ToArray(std::move(points), {n, 3});
        out["labels"] = ToArray(std::move(scan.raw_labels), {n});
        out["classes"] = ToArray(std::move(classes), {n});
        out["pose"] = MatrixToArray(run_->T_session_sensor(k).matrix());
        out["time"] = run_->poses()[k].time_s;
        return out;
    }

    [[nodiscard]] std::string session_name() const { return spec_.sessions[session_].name; }
    [[nodiscard]] size_t sessions() const { return spec_.sessions.size(); }

private:
    sim::SceneSpec spec_;
    size_t session_ = 0;
    std::unique_ptr<sim::SessionSimulation> run_;
};

}  // namespace

void RegisterSimulation(py::module_& m) {
    py::class_<Simulation>(m, "_Simulation")
        .def(py::init<const std::string&, size_t, const std::string&, std::optional<uint64_t>,
                      int>(),
             py::arg("scene"), py::arg("session") = 0, py::arg("sensor") = "",
             py::arg("seed") = py::none(), py::arg("max_scans") = 0)
        .def("__len__", &Simulation::size)
        .def("scan", &Simulation::Scan, py::arg("index"))
        .def_property_readonly("session_name", &Simulation::session_name)
        .def_property_readonly("sessions", &Simulation::sessions);
}

}  // namespace strata::python
