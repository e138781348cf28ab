// The analyses and registrations of strata.Map: each goes through the pipeline use case the
// program runs (strata diff, vehicles, walls, register, localize), answered with the keys of
// the program's JSON report plus arrays.
#include <pybind11/stl.h>

#include <cmath>
#include <memory>

#include "Analyses.hpp"
#include "Arrays.hpp"
#include "StoredMap.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/core/Region.hpp"
#include "strata/pipeline/Alignment.hpp"
#include "strata/pipeline/Diff.hpp"
#include "strata/pipeline/Dynamic.hpp"
#include "strata/pipeline/Localize.hpp"
#include "strata/pipeline/MapAccess.hpp"
#include "strata/pipeline/Vehicles.hpp"
#include "strata/pipeline/Walls.hpp"
#include "strata/vehicles/VehicleReport.hpp"

namespace strata::python {

namespace {

using store::MapStore;

/// Products are stored for the newest map of a map open for writing: checked before the work.
void CheckSave(const MapStore& store, const std::string& as_of, const std::string& what) {
    if (!as_of.empty()) {
        throw InvalidArgumentError("save=True stores the " + what +
                                   " of the newest map; as_of reads an older state (give one "
                                   "of the two)");
    }
    if (!store.writable()) {
        throw InvalidArgumentError(store.dir().string() +
                                   " is open read-only; open it with read_only=False to store " +
                                   "its " + what);
    }
}

/// An analysis's memory budget as the program's --memory-budget takes it (MB, 0: no limit), in
/// bytes.
size_t BudgetBytes(double memory_budget_mb) {
    if (!(memory_budget_mb >= 0.0) || !std::isfinite(memory_budget_mb)) {
        throw InvalidArgumentError("memory_budget_mb must be a number >= 0 (0: no limit)");
    }
    return static_cast<size_t>(memory_budget_mb * 1e6);
}

/// The end of an analysis that edits the map (vehicles, dynamic): with `save`, `store()` commits
/// the edited map (its leaves move into the store: the caller reads it back from there) and the
/// report gets "commit"; otherwise the report gets the edited map itself, read-only, as "map".
/// A map read tile by tile (`whole` false) has no edited map to hand over: "map" is None, with
/// `save` too (the stored map would not fit the budget either). Read whole and stored, the report
/// has no "map" (the program's path in it is dropped): Python's Map reads the stored map back.
template <typename Outcome, typename StoreFn>
py::dict StoreOrHandOver(const StoredMap& m, py::dict report,
                         const std::shared_ptr<Outcome>& outcome, bool whole, bool save,
                         StoreFn&& store) {
    if (!whole) {
        report["map"] = py::none();
    } else if (save) {
        report.attr("pop")("map", py::none());
    }
    if (save) {
        int64_t commit = 0;
        {
            py::gil_scoped_release release;
            commit = store();
        }
        report["commit"] = commit;
        return report;
    }
    if (!whole) return report;
    MemoryMap edited;
    edited.map = std::shared_ptr<core::VoxelMap>(outcome, &outcome->cleaned);
    edited.config = m.config;
    edited.read_only = true;
    report["map"] = py::cast(std::move(edited));
    return report;
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
    const Eigen::Isometry3d guess =
        init.is_none() ? Eigen::Isometry3d::Identity() : GuessFromArray(init, "init");
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

py::dict Localize(const StoredMap& m, const py::array& points, int floor, const py::object& init,
                  double l1, double l2, double min_range, double max_range,
                  const py::object& min_overlap, const py::object& max_rmse) {
    const std::vector<Eigen::Vector3d> scan = PointsFromArray(points);
    pipeline::LocalizeOptions options;
    options.floor = floor;
    options.slice.l1_m = l1;
    options.slice.l2_m = l2;
    if (!init.is_none()) options.guess = GuessFromArray(init, "init");
    options.align.min_range_m = min_range;
    options.align.max_range_m = max_range;
    if (!min_overlap.is_none()) options.align.config.min_overlap = min_overlap.cast<double>();
    if (!max_rmse.is_none()) options.align.config.max_rmse_m = max_rmse.cast<double>();
    options.Validate();
    const MapStore& store = m.Get();
    pipeline::Localization l;
    {
        py::gil_scoped_release release;
        l = pipeline::Localize(store, scan, options);
    }
    py::dict report = ParseJson(pipeline::LocalizationJson(l).dump());
    report["pose"] = MatrixToArray(l.alignment.result.T_map_source.matrix());
    return report;
}

py::dict Walls(const StoredMap& m, const std::string& as_of, double memory_budget_mb, bool save,
               const py::kwargs& options) {
    const walls::WallConfig config = WallConfigFrom(options);
    const size_t budget = BudgetBytes(memory_budget_mb);
    MapStore& store = m.Get();
    if (save) CheckSave(store, as_of, "walls");
    pipeline::WallsOutcome outcome;
    int64_t commit = 0;
    {
        py::gil_scoped_release release;
        outcome =
            pipeline::FindWalls(store, pipeline::SelectSnapshot(store, as_of), config, budget);
        if (save) commit = pipeline::StoreWalls(store, outcome);
    }
    py::dict report = WallsReport(outcome.map, outcome.result, config);
    if (save) report["commit"] = commit;
    return report;
}

py::dict Vehicles(const StoredMap& m, const std::string& as_of, const std::string& source,
                  bool ray_check, bool refill, double memory_budget_mb, bool save) {
    vehicles::VehicleConfig config;
    config.source = vehicles::SourceFromName(source);
    config.ray_check = ray_check;
    config.refill = refill;
    const size_t budget = BudgetBytes(memory_budget_mb);
    MapStore& store = m.Get();
    if (save) CheckSave(store, as_of, "vehicles");
    auto outcome = std::make_shared<pipeline::VehiclesOutcome>();
    {
        py::gil_scoped_release release;
        *outcome =
            pipeline::ClearVehicles(store, pipeline::SelectSnapshot(store, as_of), config, budget);
    }
    py::dict report = ParseJson(vehicles::VehiclesJson(outcome->result, store.settings().origin));
    return StoreOrHandOver(m, std::move(report), outcome, outcome->tile_groups == 0, save,
                           [&] { return pipeline::StoreVehicles(store, *outcome); });
}

py::dict Dynamic(const StoredMap& m, const std::string& as_of, const std::string& session,
                 int margin, bool faces, size_t min_object, bool occupied_too,
                 bool remove_scattered, double memory_budget_mb, bool save) {
    dynamic::DynamicConfig config;
    config.margin_voxels = margin;
    config.neighbourhood = faces ? dynamic::Neighbourhood::kFaces : dynamic::Neighbourhood::kCube;
    config.min_object_voxels = min_object;
    config.occupied_too = occupied_too;
    config.keep_scattered = !remove_scattered;
    const size_t budget = BudgetBytes(memory_budget_mb);
    MapStore& store = m.Get();
    if (save) CheckSave(store, as_of, "static map");
    auto outcome = std::make_shared<pipeline::DynamicOutcome>();
    {
        py::gil_scoped_release release;
        *outcome = pipeline::FindDynamic(store, pipeline::SelectSnapshot(store, as_of), config,
                                         session, budget);
    }
    py::dict report = ParseJson(pipeline::DynamicReport(*outcome, store));
    return StoreOrHandOver(m, std::move(report), outcome, outcome->tiles == 0, save,
                           [&] { return pipeline::StoreDynamic(store, *outcome); });
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
    pipeline::DiffOptions options;
    options.from = from;
    options.to = to;
    change::ChangeQuery& query = options.query;
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
        result = pipeline::QueryChanges(store, options).result;
    }
    py::dict report = ParseJson(result.report);
    const core::VoxelMap frame = store.EmptyMap();
    report["added"] = Centers(result.changes.added, frame);
    report["removed"] = Centers(result.changes.removed, frame);
    return report;
}

}  // namespace

void AddStoredAnalyses(py::class_<StoredMap>& cls) {
    cls.def("diff", &Diff, py::arg("from_side"), py::arg("to_side"), py::arg("region"),
            py::arg("class_name"), py::arg("min_voxels"), py::arg("gap"), py::arg("tolerance"),
            py::arg("margin"), py::arg("grow"), py::arg("support"))
        .def("vehicles", &Vehicles, py::arg("as_of"), py::arg("source"), py::arg("ray_check"),
             py::arg("refill"), py::arg("memory_budget_mb"), py::arg("save"))
        .def("dynamic", &Dynamic, py::arg("as_of"), py::arg("session"), py::arg("margin"),
             py::arg("faces"), py::arg("min_object"), py::arg("occupied_too"),
             py::arg("remove_scattered"), py::arg("memory_budget_mb"), py::arg("save"))
        .def("walls", &Walls, py::arg("as_of"), py::arg("memory_budget_mb"), py::arg("save"))
        .def("register", &Register, py::arg("points"), py::arg("init"), py::arg("as_of"),
             py::arg("margin"), py::arg("min_range"), py::arg("max_range"), py::arg("min_overlap"),
             py::arg("max_rmse"))
        .def("localize", &Localize, py::arg("points"), py::arg("floor"), py::arg("init"),
             py::arg("l1"), py::arg("l2"), py::arg("min_range"), py::arg("max_range"),
             py::arg("min_overlap"), py::arg("max_rmse"));
}

}  // namespace strata::python
