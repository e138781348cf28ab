#pragma once
// strata.VoxelMap: a map held in memory (built from arrays, or a stored map's snapshot).

#include <memory>

#include "Bindings.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/integration/IntegrationConfig.hpp"
#include "strata/pipeline/IntegrationRule.hpp"

namespace strata::python {

struct MemoryMap {
    std::shared_ptr<core::VoxelMap> map;
    integration::IntegrationConfig config;
    bool read_only = false;  ///< a stored map's snapshot: queries and export only
};

/// The integration rule Python's keyword arguments ask for (as `strata integrate`'s flags).
[[nodiscard]] pipeline::RuleRequest RuleFrom(double max_range, double min_range, bool points_only,
                                             bool keep_point_means);
/// The integration counts of one scan as a dict (points, dropped, clipped).
[[nodiscard]] py::dict UpdateCounts(size_t points, size_t dropped, size_t clipped);

}  // namespace strata::python
