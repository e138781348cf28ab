#pragma once

#include <filesystem>

#include "strata/columns/ColumnStats.hpp"

namespace strata::columns {

/// @brief What a column heat map shows.
enum class ColumnValue { kPoints, kVoxels, kExtent };

/// @brief A top-down heat map of column statistics: black for empty columns, then a dark blue ->
/// red -> yellow -> white ramp over log(1 + value) up to the largest value; a scale bar. One
/// pixel per column, or coarser (the largest value of the block wins) so the image stays within
/// `max_pixels` on a side. Written all or nothing; throws IoError naming `path`.
void WriteColumnPng(const ColumnGrid& columns, double voxel_size, const std::filesystem::path& path,
                    ColumnValue value = ColumnValue::kPoints, int max_pixels = 3000);

}  // namespace strata::columns
