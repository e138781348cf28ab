#pragma once
// The export use case, shared by `strata export` and Python's `Map.export`.

#include <filesystem>
#include <string>

#include "strata/core/VoxelMap.hpp"

namespace strata::pipeline {

/// @brief How a map is written for viewers.
struct ExportOptions {
    /// vdb, bt, ot, ply or png; empty: from the output file's extension.
    std::string format;
    int pixels_per_voxel = 2;  ///< PNG scale
    /// PNG colours: "class", "height", or "auto" (height when the map has no labels).
    std::string color = "auto";

    /// @brief Throws InvalidArgumentError naming the first bad field.
    void Validate() const;
};

/// @brief The format an export to `out` writes: `options.format`, else the extension of `out`.
/// @throw InvalidArgumentError for an unknown format, a missing extension, or an OctoMap file
/// whose name does not end in its format.
[[nodiscard]] std::string ExportFormat(const std::filesystem::path& out,
                                       const ExportOptions& options);

/// @brief Writes `map` to `out` (VDB, OctoMap .bt/.ot, PLY or a top-down PNG); returns the
/// format written. The file is checked before anything is written (ExportFormat).
std::string ExportMap(const core::VoxelMap& map, const std::filesystem::path& out,
                      const ExportOptions& options = {});

}  // namespace strata::pipeline
