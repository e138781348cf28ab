#pragma once
// One Register function per file of the module; Module.cpp calls them in order.

#include <pybind11/pybind11.h>

namespace strata::python {

namespace py = pybind11;

/// strata.Error and one subclass per kind of strata::Error (include/strata/core/Error.hpp).
void RegisterErrors(py::module_& m);
/// read_points, read_kitti, read_bag.
void RegisterReaders(py::module_& m);
/// The simulator, one scan at a time (strata.simulate wraps it in a generator).
void RegisterSimulation(py::module_& m);
/// VoxelMap: a map in memory, its integration, queries and export.
void RegisterMemoryMap(py::module_& m);
/// Map and Session: a map on disk (StoredMap.cpp, Session.cpp, StoredAnalyses.cpp).
void RegisterStoredMap(py::module_& m);

}  // namespace strata::python
