// The compiled part of `import strata` (python/strata/__init__.py re-exports it).
#include <openvdb/openvdb.h>

#include "Bindings.hpp"
#include "strata/core/Labels.hpp"

PYBIND11_MODULE(_strata, m) {
    namespace python = strata::python;
    m.doc() = "strata's compiled core; use `import strata`.";
    openvdb::initialize();
    python::RegisterErrors(m);
    python::RegisterReaders(m);
    python::RegisterSimulation(m);
    python::RegisterMemoryMap(m);
    python::RegisterStoredMap(m);
    pybind11::list classes;
    for (int k = 0; k < strata::core::kNumClasses; ++k) {
        classes.append(strata::core::ClassName(static_cast<strata::core::SemanticClass>(k)));
    }
    m.attr("CLASSES") = pybind11::tuple(classes);
}
