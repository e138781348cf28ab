// strata.Map: a map on disk (the store, docs/store.md), opened or created through the pipeline
// library; its sessions (Session.cpp) and analyses (StoredAnalyses.cpp) are added here.
#include "StoredMap.hpp"

#include <pybind11/stl.h>

#include <memory>

#include "Analyses.hpp"
#include "Arrays.hpp"
#include "Bindings.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/Export.hpp"
#include "strata/pipeline/Info.hpp"
#include "strata/pipeline/MapAccess.hpp"
#include "strata/pipeline/OpenOrCreate.hpp"

namespace strata::python {

using store::MapStore;

MapStore& StoredMap::Get() const {
    if (!store) throw InvalidArgumentError("the map is closed");
    return *store;
}

MemoryMap StoredMap::Load(const std::string& as_of) const {
    MemoryMap m;
    m.config = config;
    m.read_only = true;
    const MapStore& s = Get();
    py::gil_scoped_release release;
    m.map = std::make_shared<core::VoxelMap>(s.LoadMap(pipeline::SelectSnapshot(s, as_of)));
    return m;
}

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

namespace {

StoredMap CreateStoredMap(const std::string& path, double voxel, double tile_size,
                          const py::object& origin, double max_range, double min_range,
                          bool points_only, bool keep_point_means) {
    pipeline::MapRequest request;  // the settings `strata integrate` gives a new map
    request.voxel_size_m = voxel;
    request.tile_size_m = tile_size;
    if (!origin.is_none()) request.origin = Vector3FromObject(origin, "origin");
    request.rule = RuleFrom(max_range, min_range, points_only, keep_point_means);
    py::gil_scoped_release release;
    pipeline::OpenedMap created = pipeline::CreateMap(path, request);
    StoredMap m;
    m.config = created.rule;  // recorded: every later session fuses alike
    m.store = std::make_shared<MapStore>(std::move(created.map));
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

std::string ExportStoredMap(const StoredMap& self, const std::string& path,
                            const std::string& format, const std::string& as_of,
                            const std::string& points) {
    pipeline::ExportOptions options;
    options.format = format;
    options.points = points;
    options.memory_budget_bytes = 0;  // as Map.load: the whole snapshot in memory when it must be
    const MapStore& store = self.Get();
    py::gil_scoped_release release;
    return pipeline::ExportStored(store, pipeline::SelectSnapshot(store, as_of), path, options)
        .format;
}

py::object Info(const StoredMap& self, const std::string& as_of) {
    std::string text;
    {
        py::gil_scoped_release release;
        text = pipeline::DescribeMap(self.Get(), as_of).dump();
    }
    return ParseJson(text);
}

}  // namespace

void RegisterStoredMap(py::module_& m) {
    py::class_<StoredMap> cls(m, "_Map");
    cls.def_static("create", &CreateStoredMap, py::arg("path"), py::arg("voxel"),
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
        .def("info", &Info, py::arg("as_of") = "")
        .def("session_id",
             [](const StoredMap& self, const std::string& id_or_name) {
                 return self.Get().FindSession(id_or_name);
             })
        .def("export", &ExportStoredMap, py::arg("path"), py::arg("format") = "",
             py::arg("as_of") = "", py::arg("points") = "")
        .def_property_readonly("path",
                               [](const StoredMap& self) { return self.Get().dir().string(); })
        .def_property_readonly("writable",
                               [](const StoredMap& self) { return self.Get().writable(); })
        .def_property_readonly(
            "voxel_size", [](const StoredMap& self) { return self.Get().settings().voxel_size_m; });
    AddStoredAnalyses(cls);
    RegisterSession(m);
}

}  // namespace strata::python
