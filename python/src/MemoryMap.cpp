#include "MemoryMap.hpp"

#include <pybind11/stl/filesystem.h>

#include "Analyses.hpp"
#include "Queries.hpp"
#include "strata/core/Error.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/pipeline/Export.hpp"

namespace strata::python {

namespace {

MemoryMap CreateMemoryMap(double voxel, double max_range, double min_range, bool points_only,
                          bool keep_point_means) {
    MemoryMap m;
    const pipeline::RuleRequest rule =
        RuleFrom(max_range, min_range, points_only, keep_point_means);
    rule.Validate();
    m.config = rule.ForNewMap();
    if (!(voxel > 0.0)) throw InvalidArgumentError("voxel must be > 0 (metres)");
    m.map = std::make_shared<core::VoxelMap>(core::VoxelMap::Create(voxel));
    return m;
}

py::dict IntegrateInMemory(MemoryMap& m, const py::array& points, const py::array& pose,
                           const py::object& labels, const py::object& classes,
                           const py::object& ray_origins, const py::object& ray_starts) {
    if (m.read_only) {
        throw InvalidArgumentError(
            "this VoxelMap is a stored map's snapshot; integrate through "
            "Map.session() instead");
    }
    const core::Scan scan = ScanFromArrays(points, pose, labels, classes, ray_origins, ray_starts);
    integration::ScanUpdate update;
    {
        py::gil_scoped_release release;
        update = integration::Integrator(*m.map, m.config).Integrate(scan);
    }
    return UpdateCounts(update.points, update.dropped, update.clipped);
}

std::string ExportMemoryMap(const MemoryMap& m, const std::filesystem::path& path,
                            const std::string& format, const std::string& color) {
    pipeline::ExportOptions options;
    options.format = format;
    options.color = color;
    py::gil_scoped_release release;
    return pipeline::ExportMap(*m.map, path, options);
}

py::dict WallsInMemory(const MemoryMap& self, const py::kwargs& options) {
    const walls::WallConfig config = WallConfigFrom(options);
    walls::WallResult result;
    {
        py::gil_scoped_release release;
        result = walls::FindWalls(*self.map, config);
    }
    return WallsReport(*self.map, result, config);
}

}  // namespace

pipeline::RuleRequest RuleFrom(double max_range, double min_range, bool points_only,
                               bool keep_point_means) {
    pipeline::RuleRequest rule;
    rule.max_range_m = max_range;
    rule.min_range_m = min_range;
    rule.points_only = points_only;
    rule.keep_point_means = keep_point_means;
    return rule;
}

py::dict UpdateCounts(size_t points, size_t dropped, size_t clipped) {
    py::dict out;
    out["points"] = points;
    out["dropped"] = dropped;
    out["clipped"] = clipped;
    return out;
}

void RegisterMemoryMap(py::module_& m) {
    py::class_<MemoryMap>(m, "VoxelMap", R"doc(
A map held in memory: scans integrated from numpy arrays with OctoMap's occupancy rule
(docs/integration.md), queried and exported without a store on disk. Stored maps
(strata.Map) hand out their snapshots as read-only VoxelMaps.)doc")
        .def(py::init(&CreateMemoryMap), py::arg("voxel") = 0.2, py::arg("max_range") = 50.0,
             py::arg("min_range") = 0.0, py::arg("points_only") = false,
             py::arg("keep_point_means") = true,
             "An empty map with cubic voxels of `voxel` metres.")
        .def("integrate", &IntegrateInMemory, py::arg("points"), py::arg("pose"),
             py::arg("labels") = py::none(), py::arg("classes") = py::none(),
             py::arg("ray_origins") = py::none(), py::arg("ray_starts") = py::none(),
             R"doc(Integrates one scan.

points: (N, 3) float32 or float64, sensor frame, metres.
pose: (4, 4) or (3, 4) sensor-to-map transform.
labels: optional (N,) SemanticKITTI ids (class | instance << 16); or
classes: optional (N,) strata class ids (strata.CLASSES).
ray_origins, ray_starts: optional (R, 3) sensor-frame origins and (R,) first points: the rays
of points ray_starts[r] up to ray_starts[r + 1] start at ray_origins[r] (a deskewed sweep,
as strata.read_bag gives it); by default every ray starts at the sensor.
Returns {"points", "dropped", "clipped"} counts.)doc")
        .def(
            "occupancy",
            [](const MemoryMap& self, const py::array& p) { return QueryOccupancy(*self.map, p); },
            py::arg("points"),
            "State (-1 unknown, 0 free, 1 occupied), log_odds, label and hits at (N, 3) "
            "map-frame points.")
        .def(
            "voxels",
            [](const MemoryMap& self, const py::object& lo, const py::object& hi,
               bool occupied_only) { return QueryBox(*self.map, lo, hi, occupied_only); },
            py::arg("lo"), py::arg("hi"), py::arg("occupied_only") = false,
            "Observed voxels whose centres lie in the box [lo, hi]: ijk, center, log_odds, "
            "label, label_weight, hits (one row per voxel).")
        .def(
            "columns",
            [](const MemoryMap& self, int window) { return QueryColumns(*self.map, window); },
            py::arg("window") = 0,
            "Column statistics as 2D arrays [row j, column i]: points, voxels, z_min, z_max, "
            "extent, classes (rows, cols, len(strata.CLASSES)); x0, y0, cell place them.")
        .def(
            "info", [](const MemoryMap& self) { return DescribeMap(*self.map); },
            "Voxel size, origin and voxel counts.")
        .def("export", &ExportMemoryMap, py::arg("path"), py::arg("format") = "",
             py::arg("color") = "auto",
             "Writes the map for viewers: vdb, bt, ot, ply, pcd or png (default: from the name).")
        .def("walls", &WallsInMemory,
             R"doc(Walls and their slant angles (docs/walls.md), as `strata walls --json`
reports them (walls, stats, config, ...) plus "voxels": center, slant_deg and wall_id of every
wall voxel. Keyword options are WallConfig's fields (window_m=1.0, level_to_ground=False, ...).)doc")
        .def_property_readonly("voxel_size",
                               [](const MemoryMap& self) { return self.map->voxel_size; });
}

}  // namespace strata::python
