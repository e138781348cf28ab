// strata.Session's compiled half: one session written into a map on disk through the
// pipeline's NewSession, the writer `strata integrate` uses too.
#include <memory>
#include <optional>

#include "Arrays.hpp"
#include "StoredMap.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/NewSession.hpp"

namespace strata::python {

namespace {

/// Scans go in through `integrate`; `commit` records them all in one transaction; `abort` (or
/// an exception in a `with` block) leaves the map as it was.
class Session {
public:
    Session(const StoredMap& map, const std::string& name, double memory_budget_mb)
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
        session_ = std::make_unique<pipeline::NewSession>(*store_, map.config, options);
    }

    py::dict Integrate(const py::array& points, const py::array& pose, const py::object& labels,
                       const py::object& classes, const py::object& ray_origins,
                       const py::object& ray_starts) {
        pipeline::NewSession& session = Writer();
        const core::Scan scan =
            ScanFromArrays(points, pose, labels, classes, ray_origins, ray_starts);
        integration::ScanUpdate update;
        {
            py::gil_scoped_release release;
            update = session.Integrate(scan);
        }
        return UpdateCounts(update.points, update.dropped, update.clipped);
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
    std::optional<py::dict> committed_;
};

}  // namespace

void RegisterSession(py::module_& m) {
    py::class_<Session>(m, "_Session")
        .def(py::init<const StoredMap&, const std::string&, double>(), py::arg("map"),
             py::arg("name"), py::arg("memory_budget_mb") = 0.0)
        .def("integrate", &Session::Integrate, py::arg("points"), py::arg("pose"),
             py::arg("labels") = py::none(), py::arg("classes") = py::none(),
             py::arg("ray_origins") = py::none(), py::arg("ray_starts") = py::none())
        .def("commit", &Session::Commit)
        .def("abort", &Session::Abort)
        .def_property_readonly("record", &Session::Record);
}

}  // namespace strata::python
