#pragma once
// Parts of a scan update, for processes that own some tiles of a map each (docs/scale.md): the
// one that computed an update keeps or sends each part to the process that applies it.

#include <functional>
#include <string>
#include <string_view>

#include "strata/core/GridTypes.hpp"
#include "strata/integration/Integrator.hpp"

namespace strata::integration {

/// @brief Accepts or rejects one leaf of the map's index space by its origin (a multiple of 8 on
/// every axis).
using LeafFilter = std::function<bool(const openvdb::Coord& leaf_origin)>;

/// @brief The part of `update` in the leaves `keep` accepts: its free and occupied voxels and
/// endpoint groups there, in the same order; the point counts stay those of the whole scan.
/// Applying every part of a partition of the leaves gives each voxel exactly what applying the
/// whole update gives it (updates act voxel by voxel).
[[nodiscard]] ScanUpdate SelectUpdate(const ScanUpdate& update, const LeafFilter& keep);

/// @brief Whether `keep` accepts every leaf of `update` (its free, occupied and endpoint voxels):
/// then SelectUpdate would copy it whole.
[[nodiscard]] bool AllLeaves(const ScanUpdate& update, const LeafFilter& keep);

/// @brief The update as bytes (little-endian, versioned), to hand to another process; with
/// `keep`, only its part in the leaves `keep` accepts (the bytes of EncodeUpdate(SelectUpdate(
/// update, keep)), without building that part's trees).
[[nodiscard]] std::string EncodeUpdate(const ScanUpdate& update, const LeafFilter& keep = {});

/// @brief The update EncodeUpdate wrote.
/// @throw FormatError when `bytes` is not an encoded update (truncated, trailing bytes, a bad
/// version, leaf origin or class), naming `what`.
[[nodiscard]] ScanUpdate DecodeUpdate(std::string_view bytes, const std::string& what);

}  // namespace strata::integration
