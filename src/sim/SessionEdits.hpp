#pragma once

// Applying session edits to the object list, and what changed for ground_truth.json (private).
#include <vector>

#include "strata/sim/GroundTruth.hpp"
#include "strata/sim/SceneSpec.hpp"

namespace strata::sim::detail {

struct SessionObjects {
    std::vector<ObjectSpec> objects;
    std::vector<EditTruth> edits;  ///< changes of this session relative to the one before
};

/// Objects of a session and its edits; throws FormatError for an edit that does
/// not fit its object (unknown name, moving a wall, demolishing a vehicle, ...).
[[nodiscard]] SessionObjects ApplySessionEdits(const SceneSpec& spec, size_t session);

}  // namespace strata::sim::detail
