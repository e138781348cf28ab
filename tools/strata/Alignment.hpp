#pragma once
// Shared by register, integrate --align, stack and localize: the options of an alignment and how
// its result is printed. The alignment itself is the pipeline's (shared with Python).

#include <CLI/CLI.hpp>
#include <ostream>
#include <vector>

#include "strata/pipeline/Alignment.hpp"

namespace strata::tools {

struct AlignArgs : pipeline::AlignOptions {
    std::vector<double> init;  // x,y,z,yaw_deg: the guess of T_map_source
};

/// Adds --init, --min-overlap, --max-rmse, --margin and (with `ranges`) --min-range, --max-range.
void AddAlignOptions(CLI::App& cmd, AlignArgs& args, bool ranges = true);
/// The alignment the options ask for: how, and the guess from --init (or the identity).
[[nodiscard]] pipeline::AlignRequest AlignRequestOf(const AlignArgs& args);

/// A human summary of an alignment.
void PrintAlignment(const pipeline::MapAlignment& a, std::ostream& out);

}  // namespace strata::tools
