#pragma once
// strata.Map's compiled half: a map on disk (the store, docs/store.md). StoredMap.cpp opens and
// reads it, Session.cpp writes sessions into it, StoredAnalyses.cpp runs the analyses on it;
// every call goes through the pipeline library or the store.

#include <pybind11/pybind11.h>

#include <memory>
#include <string>

#include "MemoryMap.hpp"
#include "strata/integration/IntegrationConfig.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::python {

namespace py = pybind11;

struct StoredMap {
    std::shared_ptr<store::MapStore> store;  ///< null once closed
    integration::IntegrationConfig config;   ///< the map's integration rule

    /// The store; InvalidArgumentError once the map is closed.
    [[nodiscard]] store::MapStore& Get() const;
    /// A snapshot as a read-only map in memory; `as_of` empty: the newest.
    [[nodiscard]] MemoryMap Load(const std::string& as_of) const;
};

/// A session's record as a dict (id, name, source, scans, points, times, commit, alignment,
/// notes).
[[nodiscard]] py::dict SessionDict(const store::SessionRecord& s);

/// Map.diff, vehicles, walls, register and localize.
void AddStoredAnalyses(py::class_<StoredMap>& cls);
/// strata._Session: one session written into a StoredMap.
void RegisterSession(py::module_& m);

}  // namespace strata::python
