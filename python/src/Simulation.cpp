// The simulator from Python, one scan at a time (strata.simulate is the generator around it).
// Each scan is what `strata simulate` would write for it: float32 points in the sensor frame,
// SemanticKITTI labels, the pose in the session's frame; so a map integrated from these arrays
// equals `strata integrate` on the written sequence.
#include <pybind11/stl.h>

#include <memory>
#include <optional>

#include "Arrays.hpp"
#include "Bindings.hpp"
#include "strata/core/Error.hpp"
#include "strata/sim/Scene.hpp"
#include "strata/sim/SceneSpec.hpp"
#include "strata/sim/SensorModel.hpp"
#include "strata/sim/SimulateScene.hpp"
#include "strata/sim/Simulator.hpp"
#include "strata/sim/Trajectory.hpp"

namespace strata::python {

namespace {

class Simulation {
public:
    Simulation(const std::string& scene, size_t session, const std::string& sensor,
               std::optional<uint64_t> seed, int max_scans) {
        py::gil_scoped_release release;
        spec_ = scene == "demo" ? sim::DemoStreetScene() : sim::LoadSceneSpec(scene);
        spec_.Validate();
        if (session >= spec_.sessions.size()) {
            throw InvalidArgumentError(scene + " has " + std::to_string(spec_.sessions.size()) +
                                       " session(s); session " + std::to_string(session) +
                                       " does not exist");
        }
        if (max_scans < 0) throw InvalidArgumentError("max_scans must be >= 0");
        sensor_ = sim::SensorModel::FromName(sensor.empty() ? spec_.sensor : sensor);
        sensor_.Validate();
        session_ = session;
        seed_ = seed.value_or(spec_.seed);
        simulator_ = std::make_unique<sim::Simulator>(sim::BuildScene(spec_, session));
        sim::TrajectorySpec trajectory = spec_.sessions[session].trajectory;
        if (max_scans > 0) trajectory.max_scans = std::min(trajectory.max_scans, max_scans);
        poses_ = sim::PlanScanPoses(trajectory, *simulator_, sensor_.rate_hz);
    }

    [[nodiscard]] size_t size() const { return poses_.size(); }

    [[nodiscard]] py::dict Scan(size_t k) const {
        if (k >= poses_.size()) {
            throw py::index_error("scan " + std::to_string(k) + " of " +
                                  std::to_string(poses_.size()));
        }
        sim::SimulatedScan scan;
        {
            py::gil_scoped_release release;
            sim::SweepRequest request;
            request.T_world_sensor = poses_[k].T_world_sensor;
            request.seed = seed_;
            request.scan_index = (uint64_t{session_} << 32) | k;  // as SimulateSceneToSequence
            request.time_s = poses_[k].time_s;
            scan = simulator_->SimulateSweep(request, sensor_);
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
        const Eigen::Isometry3d T_session_sensor =
            spec_.sessions[session_].T_world_session.inverse() * poses_[k].T_world_sensor;
        py::dict out;
        out["points"] = ToArray(std::move(points), {n, 3});
        out["labels"] = ToArray(std::move(scan.raw_labels), {n});
        out["classes"] = ToArray(std::move(classes), {n});
        out["pose"] = MatrixToArray(T_session_sensor.matrix());
        out["time"] = poses_[k].time_s;
        return out;
    }

    [[nodiscard]] std::string session_name() const { return spec_.sessions[session_].name; }
    [[nodiscard]] size_t sessions() const { return spec_.sessions.size(); }

private:
    sim::SceneSpec spec_;
    sim::SensorModel sensor_;
    size_t session_ = 0;
    uint64_t seed_ = 0;
    std::unique_ptr<sim::Simulator> simulator_;
    std::vector<sim::ScanPose> poses_;
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
