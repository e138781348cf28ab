// strata.Session's compiled half: one session written into a map on disk through the
// pipeline's NewSession, the writer `strata integrate` uses too.
#include <memory>
#include <optional>

#include "Analyses.hpp"
#include "Arrays.hpp"
#include "StoredMap.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/NewSession.hpp"
#include "strata/pipeline/Odometry.hpp"
#include "strata/recordings/Deskew.hpp"

namespace strata::python {

namespace {

/// Scans go in through `integrate`; `commit` records them all in one transaction; `abort` (or
/// an exception in a `with` block) leaves the map as it was.
class Session {
public:
    Session(const StoredMap& map, const std::string& name, double memory_budget_mb, bool odometry,
            const py::object& start)
        : store_(map.store) {
        if (!store_) throw InvalidArgumentError("the map is closed");
        if (!store_->writable()) {
            throw InvalidArgumentError(store_->dir().string() +
                                       " is open read-only; open it with read_only=False to "
                                       "add a session");
        }
        if (!(memory_budget_mb >= 0.0)) throw InvalidArgumentError("memory_budget_mb must be >= 0");
        store::SessionOptions options;
        options.name = name;
        options.source = "python";
        options.memory_budget_bytes = static_cast<size_t>(memory_budget_mb * 1e6);
        std::optional<pipeline::OdometryStart> in_map;
        if (!start.is_none()) {
            if (!odometry) {
                throw InvalidArgumentError("start is for a session made with odometry=True");
            }
            // The map as it is now: what this session writes is not read back.
            in_map = pipeline::OdometryStart{store_.get(), store_->Latest(), {}, {}};
            in_map->align.guess = GuessFromArray(start, "start");
        }
        session_ = std::make_unique<pipeline::NewSession>(*store_, map.config, options);
        if (odometry) odometry_.emplace(registration::OdometryConfig{}, std::move(in_map));
    }

    py::dict Integrate(const py::array& points, const py::object& pose, const py::object& labels,
                       const py::object& classes, const py::object& ray_origins,
                       const py::object& ray_starts, const py::object& times, double time) {
        pipeline::NewSession& session = Writer();
        if (odometry_.has_value() != pose.is_none()) {
            throw InvalidArgumentError(odometry_ ? "this session estimates its poses "
                                                   "(odometry=True): give points without a pose"
                                                 : "integrate() needs a pose (or a session "
                                                   "made with odometry=True)");
        }
        // With odometry the pose comes after the points are read: identity until then.
        const py::array given = odometry_ ? py::array(MatrixToArray(Eigen::Matrix4d::Identity()))
                                          : py::array::ensure(pose);
        if (!given) throw InvalidArgumentError("pose must be a (4, 4) or (3, 4) array");
        core::Scan scan = ScanFromArrays(points, given, labels, classes, ray_origins, ray_starts);
        scan.time_s = time;
        if (!times.is_none()) {
            if (!odometry_) {
                throw InvalidArgumentError(
                    "per-point times are for a session made with odometry=True (a posed "
                    "recording's sweeps come deskewed already)");
            }
            scan.times_s = TimesFromArray(py::array::ensure(times), scan.points.size());
            if (!stamps_.empty() && !(time > stamps_.back())) {
                throw InvalidArgumentError(
                    "a scan with its points' times needs its own time, after the last scan's (" +
                    std::to_string(stamps_.back()) + " s); got " + std::to_string(time));
            }
        }
        integration::ScanUpdate update;
        {
            py::gil_scoped_release release;
            if (odometry_) {
                // With its points' times, a sweep is predicted and deskewed over its instant
                // and integrated deskewed by the motion found (docs/odometry.md).
                const registration::OdometryStep step = odometry_->Register(scan);
                if (!step.registered) {
                    throw RefusedError("scan " + std::to_string(session.scans()) +
                                       " (numpy): " + step.failure);
                }
                scan.T_world_sensor = step.T_world_sensor;
                if (step.ground) ground_ = step.ground;
                stamps_.push_back(scan.time_s);
                if (!scan.times_s.empty()) {
                    recordings::DeskewAlong(scan, stamps_, odometry_->poses());
                }
            }
            update = session.Integrate(scan);
        }
        return UpdateCounts(update.points, update.dropped, update.clipped);
    }

    // The poses the odometry estimated, (N, 4, 4); None for a session given its poses.
    [[nodiscard]] py::object Poses() const {
        if (!odometry_) return py::none();
        std::vector<double> flat;
        for (const Eigen::Isometry3d& T : odometry_->poses()) {
            for (int r = 0; r < 4; ++r) {
                for (int c = 0; c < 4; ++c) flat.push_back(T.matrix()(r, c));
            }
        }
        const auto n = static_cast<py::ssize_t>(odometry_->poses().size());
        return ToArray(std::move(flat), {n, 4, 4});
    }

    // Where the map's up came from (docs/odometry.md, "Gravity"); None without odometry or
    // before the first scan.
    [[nodiscard]] py::object Gravity() const {
        if (odometry_ && odometry_->alignment()) {
            py::dict d;
            d["source"] = "map";
            d["map_points"] = odometry_->map_points_used().value_or(0);
            return d;
        }
        if (!ground_) return py::none();
        py::dict d;
        d["source"] = ground_->found ? "ground_plane" : "first_scan";
        d["tilt_deg"] = ground_->tilt_deg;
        d["points"] = ground_->points;
        d["rms_m"] = ground_->rms_m;
        d["height_m"] = ground_->height_m;
        d["failure"] = ground_->failure;
        return d;
    }

    // The first scan's alignment to the map (as Map.register reports it), for a session that
    // started in the map once that scan is in; else None.
    [[nodiscard]] py::object Alignment() const {
        if (!odometry_ || !odometry_->alignment()) return py::none();
        const pipeline::MapAlignment& a = *odometry_->alignment();
        py::dict report = ParseJson(pipeline::AlignmentJson(a).dump());
        report["pose"] = MatrixToArray(a.result.T_map_source.matrix());
        return report;
    }

    py::dict Commit() {
        pipeline::NewSession& session = Writer();
        store::SessionRecord record;
        {
            py::gil_scoped_release release;
            record = session.Commit();
        }
        session_.reset();
        committed_ = SessionDict(record);
        return *committed_;
    }

    void Abort() {
        py::gil_scoped_release release;
        session_.reset();  // the writer removes the files it wrote; the catalog never saw them
    }

    [[nodiscard]] py::object Record() const {
        return committed_ ? py::object(*committed_) : py::object(py::none());
    }

private:
    pipeline::NewSession& Writer() {
        if (!session_) throw InvalidArgumentError("the session is committed or aborted already");
        return *session_;
    }

    std::shared_ptr<store::MapStore> store_;  // the writer refers to it: kept alive with it
    std::unique_ptr<pipeline::NewSession> session_;
    std::optional<pipeline::SessionOdometry> odometry_;  // odometry=True: poses estimated
    std::vector<double> stamps_;                         // of the poses the odometry found
    std::optional<registration::GroundLevel> ground_;    // what levelled the odometry's world
    std::optional<py::dict> committed_;
};

}  // namespace

void RegisterSession(py::module_& m) {
    py::class_<Session>(m, "_Session")
        .def(py::init<const StoredMap&, const std::string&, double, bool, const py::object&>(),
             py::arg("map"), py::arg("name"), py::arg("memory_budget_mb") = 0.0,
             py::arg("odometry") = false, py::arg("start") = py::none())
        .def("integrate", &Session::Integrate, py::arg("points"), py::arg("pose"),
             py::arg("labels") = py::none(), py::arg("classes") = py::none(),
             py::arg("ray_origins") = py::none(), py::arg("ray_starts") = py::none(),
             py::arg("times") = py::none(), py::arg("time") = 0.0)
        .def("commit", &Session::Commit)
        .def("abort", &Session::Abort)
        .def_property_readonly("record", &Session::Record)
        .def_property_readonly("poses", &Session::Poses)
        .def_property_readonly("gravity", &Session::Gravity)
        .def_property_readonly("alignment", &Session::Alignment);
}

}  // namespace strata::python
