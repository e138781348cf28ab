#pragma once
// Shared by register, integrate --align, stack and localize: the options of an alignment, the
// cloud to align, the map region it is aligned to, and how the result is reported.

#include <CLI/CLI.hpp>
#include <ostream>
#include <vector>

#include "ScanSource.hpp"
#include "strata/pipeline/Alignment.hpp"

namespace strata::tools {

// The alignment itself is the pipeline's (shared with Python); the program adds --init.
using pipeline::AlignmentJson;
using pipeline::AlignToMap;
using pipeline::MapAlignment;
using pipeline::RequireAccepted;
using pipeline::SourceCloud;

struct AlignArgs : pipeline::AlignOptions {
    std::vector<double> init;  // x,y,z,yaw_deg: the guess of T_map_source
};

/// Adds --init, --min-overlap, --max-rmse, --margin and (with `ranges`) --min-range, --max-range.
void AddAlignOptions(CLI::App& cmd, AlignArgs& args, bool ranges = true);
/// The guess from --init, or the identity.
[[nodiscard]] Eigen::Isometry3d InitialGuess(const AlignArgs& args);

/// Reads every scan of `source`. A single scan without poses (`as_is`) stays in its own frame;
/// anything else is accumulated in the frame of the scans' poses.
[[nodiscard]] SourceCloud ReadSourceCloud(const ScanSource& source, bool as_is,
                                          const AlignArgs& args);

/// A human summary of an alignment.
void PrintAlignment(const MapAlignment& a, std::ostream& out);

}  // namespace strata::tools
