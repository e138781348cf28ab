#pragma once

#include <filesystem>

#include "strata/core/VoxelMap.hpp"
#include "strata/dynamic/Dynamic.hpp"

namespace strata::dynamic {

/// @brief Top-down picture (docs/dynamic.md), two panels side by side: the raw map with the
/// removed voxels in the colour of class `dynamic`, and the static map.
/// @throw IoError naming `path` when it cannot be written.
void WriteDynamicPng(const core::VoxelMap& raw, const core::VoxelMap& static_map,
                     const DynamicResult& result, const std::filesystem::path& path);

}  // namespace strata::dynamic
