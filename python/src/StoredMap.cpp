// strata.Map: a map on disk (the store, docs/store.md) and its sessions. Every call into the
// store from Python is in this file, so a change of the store's API touches one place.
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <optional>

#include "Analyses.hpp"
#include "Arrays.hpp"
#include "Bindings.hpp"
#include "MemoryMap.hpp"
#include "Queries.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/core/Region.hpp"
#include "strata/pipeline/Alignment.hpp"
#include "strata/pipeline/Diff.hpp"
#include "strata/pipeline/Export.hpp"
#include "strata/pipeline/Info.hpp"
#include "strata/pipeline/MapAccess.hpp"
#include "strata/pipeline/Vehicles.hpp"
#include "strata/store/MapStore.hpp"
#include "strata/store/SessionWriter.hpp"
#include "strata/vehicles/VehicleReport.hpp"

namespace strata::python {

namespace {

using store::MapStore;

struct StoredMap {
    std::shared_ptr<MapStore> store;  ///< null once closed
    integration::IntegrationConfig config;

    MapStore& Get() const {
        if (!store) throw InvalidArgumentError("the map is closed");
        return *store;
    }
    /// A snapshot as a read-only map in memory; `as_of` empty: the newest.
    MemoryMap Load(const std::string& as_of) const {
        MemoryMap m;
        m.config = config;
        m.read_only = true;
        const MapStore& s = Get();
        py::gil_scoped_release release;
        m.map = std::make_shared<core::VoxelMap>(s.LoadMap(pipeline::SelectSnapshot(s, as_of)));
        return m;
    }
};

py::dict SessionDict(const store::SessionRecord& s) {
    py::dict d;
    d["id"] = s.id;
    d["name"] = s.name;
    d["source"] = s.source;
    d["scans"] = s.scans;
    d["points"] = s.points;
    d["start_utc"] = s.start_utc;
    d["end_utc"] = s.end_utc;
    d["commit"] = s.commit;
    d["alignment"] = MatrixToArray(s.alignment);
    d["notes"] = s.notes;
    return d;
}

StoredMap CreateStoredMap(const std::string& path, double voxel, double tile_size,
                          const py::object& origin, double max_range, double min_range,
                          bool points_only, bool keep_point_means) {
    StoredMap m;
    m.config = IntegrationRule(max_range, min_range, points_only, keep_point_means);
    store::StoreSettings settings;
    settings.voxel_size_m = voxel;
    settings.tile_size_m = tile_size;
    settings.integration = m.config;  // recorded: every later session fuses alike
    if (!origin.is_none()) settings.origin = Vector3FromObject(origin, "origin");
    if (MapStore::IsMap(path)) {
        throw InvalidArgumentError(path + " holds a map already; open it with strata.Map.open");
    }
    py::gil_scoped_release release;
    m.store = std::make_shared<MapStore>(MapStore::Create(path, settings));
    return m;
}

StoredMap OpenStoredMap(const std::string& path, bool read_only) {
    StoredMap m;
    py::gil_scoped_release release;
    m.store = std::make_shared<MapStore>(
        pipeline::OpenMap(path, read_only ? MapStore::Access::kRead : MapStore::Access::kWrite));
    m.config = m.store->settings().integration;  // the rule the map was created with
    return m;
}

py::list SessionList(const StoredMap& m) {
    py::list out;
    for (const store::SessionRecord& s : m.Get().Latest().sessions) out.append(SessionDict(s));
    return out;
}

/// T_map_source from None (identity), a (4, 4) / (3, 4) pose or (x, y, z, yaw_deg).
Eigen::Isometry3d GuessFrom(const py::object& init) {
    if (init.is_none()) return Eigen::Isometry3d::Identity();
    const py::array a = py::array::ensure(init);
    if (a && a.ndim() == 1 && a.shape(0) == 4) {
        const auto values = py::array_t<double, py::array::forcecast>(a);
        const auto v = values.unchecked<1>();
        if (!std::isfinite(v(0) + v(1) + v(2) + v(3))) {
            throw InvalidArgumentError("init must be finite");
        }
        return registration::PoseFromXyzYaw(v(0), v(1), v(2), v(3));
    }
    if (!a) throw InvalidArgumentError("init must be a 4x4 pose or (x, y, z, yaw_deg)");
    return PoseFromArray(a, "init");
}

py::dict Register(const StoredMap& m, const py::array& points, const py::object& init,
                  const std::string& as_of, double margin, double min_range, double max_range,
                  double min_overlap, double max_rmse) {
    pipeline::SourceCloud cloud;
    cloud.points = PointsFromArray(points);
    cloud.scans = 1;
    cloud.single_scan = true;
    pipeline::AlignOptions options;
    options.margin_m = margin;
    options.min_range_m = min_range;
    options.max_range_m = max_range;
    options.config.min_overlap = min_overlap;
    options.config.max_rmse_m = max_rmse;
    const Eigen::Isometry3d guess = GuessFrom(init);
    const MapStore& store = m.Get();
    pipeline::MapAlignment a;
    {
        py::gil_scoped_release release;
        a = pipeline::AlignToMap(store, pipeline::SelectSnapshot(store, as_of), cloud, guess,
                                 options);
    }
    py::dict report = ParseJson(pipeline::AlignmentJson(a).dump());
    report["pose"] = MatrixToArray(a.result.T_map_source.matrix());
    return report;
}

/// Centres of the active voxels of a change mask, (M, 3) in the map frame.
py::array_t<double> Centers(const openvdb::BoolGrid::Ptr& mask, const core::VoxelMap& frame) {
    std::vector<Eigen::Vector3d> centers;
    if (mask) {
        for (auto it = mask->cbeginValueOn(); it; ++it) {
            centers.push_back(frame.VoxelCenter(it.getCoord()));
        }
    }
    return PointsToArray(centers);
}

py::dict Diff(const StoredMap& m, const std::string& from, const std::string& to,
              const py::object& region, const std::string& class_name, size_t min_voxels, int gap,
              int tolerance, int margin, int grow, int support) {
    change::ChangeQuery query;
    if (!region.is_none()) {
        std::string text = py::isinstance<py::str>(region) ? region.cast<std::string>() : "";
        if (text.empty()) {
            for (const py::handle v : region) {
                text += (text.empty() ? "" : ",") + py::str(v).cast<std::string>();
            }
        }
        query.region = core::Region::Parse(text);
    }
    if (!class_name.empty()) query.class_filter = core::ClassFromName(class_name);
    if (min_voxels < 1) throw InvalidArgumentError("min_voxels must be at least 1");
    if (gap < 0 || tolerance < 0 || margin < 0 || grow < 0 || support < 0) {
        throw InvalidArgumentError("gap, tolerance, margin, grow and support must be >= 0");
    }
    query.min_voxels = min_voxels;
    query.gap_voxels = gap;
    query.surface_tolerance_voxels = tolerance;
    query.observed_margin_voxels = margin;
    query.grow_voxels = grow;
    query.support_depth_voxels = support;
    const MapStore& store = m.Get();
    pipeline::DiffResult result;
    {
        py::gil_scoped_release release;
        change::MapObserver observer(store, query.region);
        const pipeline::DiffSide a = pipeline::ResolveSide(from, store, observer);
        const pipeline::DiffSide b = pipeline::ResolveSide(to, store, observer);
        result = pipeline::CompareSides(a, b, store, query);
    }
    py::dict report = ParseJson(result.report);
    const core::VoxelMap frame = store.EmptyMap();
    report["added"] = Centers(result.changes.added, frame);
    report["removed"] = Centers(result.changes.removed, frame);
    return report;
}

py::dict Vehicles(const StoredMap& m, const std::string& as_of, const std::string& source,
                  bool ray_check, bool refill) {
    vehicles::VehicleConfig config;
    config.source = vehicles::SourceFromName(source);
    config.ray_check = ray_check;
    config.refill = refill;
    const MapStore& store = m.Get();
    auto outcome = std::make_shared<pipeline::VehiclesOutcome>();
    {
        py::gil_scoped_release release;
        *outcome = pipeline::ClearVehicles(store, pipeline::SelectSnapshot(store, as_of), config);
    }
    py::dict report = ParseJson(vehicles::VehiclesJson(outcome->result, outcome->cleaned.origin));
    MemoryMap cleaned;
    cleaned.map = std::shared_ptr<core::VoxelMap>(outcome, &outcome->cleaned);
    cleaned.config = m.config;
    cleaned.read_only = true;
    report["map"] = py::cast(std::move(cleaned));
    return report;
}

/// One session being written: scans go in through `integrate`; `commit` records them all in
/// one transaction; `abort` (or an exception in a `with` block) leaves the map as it was.
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
        writer_ = std::make_unique<store::SessionWriter>(*store_, map.config, options);
    }

    py::dict Integrate(const py::array& points, const py::array& pose, const py::object& labels,
                       const py::object& classes) {
        store::SessionWriter& writer = Writer();
        const core::Scan scan = ScanFromArrays(points, pose, labels, classes);
        integration::ScanUpdate update;
        {
            py::gil_scoped_release release;
            update = writer.Integrate(scan);
        }
        return UpdateCounts(update.points, update.dropped, update.clipped);
    }

    py::dict Commit() {
        store::SessionWriter& writer = Writer();
        store::SessionRecord record;
        {
            py::gil_scoped_release release;
            record = writer.Commit();
        }
        writer_.reset();
        committed_ = SessionDict(record);
        return *committed_;
    }

    void Abort() {
        py::gil_scoped_release release;
        writer_.reset();  // the writer removes the files it wrote; the catalog never saw them
    }

    [[nodiscard]] py::object Record() const {
        return committed_ ? py::object(*committed_) : py::object(py::none());
    }

private:
    store::SessionWriter& Writer() {
        if (!writer_) throw InvalidArgumentError("the session is committed or aborted already");
        return *writer_;
    }

    std::shared_ptr<MapStore> store_;  // the writer refers to it: kept alive with the session
    std::unique_ptr<store::SessionWriter> writer_;
    std::optional<py::dict> committed_;
};

}  // namespace

void RegisterStoredMap(py::module_& m) {
    py::class_<StoredMap>(m, "_Map")
        .def_static("create", &CreateStoredMap, py::arg("path"), py::arg("voxel"),
                    py::arg("tile_size"), py::arg("origin"), py::arg("max_range"),
                    py::arg("min_range"), py::arg("points_only"), py::arg("keep_point_means"))
        .def_static("open", &OpenStoredMap, py::arg("path"), py::arg("read_only"))
        .def("close",
             [](StoredMap& self) {
                 py::gil_scoped_release release;
                 self.store.reset();
             })
        .def("load", &StoredMap::Load, py::arg("as_of") = "")
        .def("sessions", &SessionList)
        .def(
            "info",
            [](const StoredMap& self, const std::string& as_of) {
                std::string text;
                {
                    py::gil_scoped_release release;
                    text = pipeline::DescribeMap(self.Get(), as_of).dump();
                }
                return ParseJson(text);
            },
            py::arg("as_of") = "")
        .def("session_id",
             [](const StoredMap& self, const std::string& id_or_name) {
                 return self.Get().FindSession(id_or_name);
             })
        .def("diff", &Diff, py::arg("from_side"), py::arg("to_side"), py::arg("region"),
             py::arg("class_name"), py::arg("min_voxels"), py::arg("gap"), py::arg("tolerance"),
             py::arg("margin"), py::arg("grow"), py::arg("support"))
        .def("vehicles", &Vehicles, py::arg("as_of"), py::arg("source"), py::arg("ray_check"),
             py::arg("refill"))
        .def("register", &Register, py::arg("points"), py::arg("init"), py::arg("as_of"),
             py::arg("margin"), py::arg("min_range"), py::arg("max_range"), py::arg("min_overlap"),
             py::arg("max_rmse"))
        .def(
            "export",
            [](const StoredMap& self, const std::string& path, const std::string& format,
               const std::string& as_of) {
                pipeline::ExportOptions options;
                options.format = format;
                (void)pipeline::ExportFormat(path, options);  // a bad name fails before any read
                const MemoryMap snapshot = self.Load(as_of);
                py::gil_scoped_release release;
                return pipeline::ExportMap(*snapshot.map, path, options);
            },
            py::arg("path"), py::arg("format") = "", py::arg("as_of") = "")
        .def_property_readonly("path",
                               [](const StoredMap& self) { return self.Get().dir().string(); })
        .def_property_readonly("writable",
                               [](const StoredMap& self) { return self.Get().writable(); })
        .def_property_readonly(
            "voxel_size", [](const StoredMap& self) { return self.Get().settings().voxel_size_m; });

    py::class_<Session>(m, "_Session")
        .def(py::init<const StoredMap&, const std::string&, double>(), py::arg("map"),
             py::arg("name"), py::arg("memory_budget_mb") = 0.0)
        .def("integrate", &Session::Integrate, py::arg("points"), py::arg("pose"),
             py::arg("labels") = py::none(), py::arg("classes") = py::none())
        .def("commit", &Session::Commit)
        .def("abort", &Session::Abort)
        .def_property_readonly("record", &Session::Record);
}

}  // namespace strata::python
