#pragma once
// The map a session is integrated into: opened when it exists, created (georeferenced) when not.

#include <filesystem>
#include <optional>

#include "strata/pipeline/IntegrationRule.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::pipeline {

/// @brief The map a command asks for. Voxel size, tile size, origin and rule are a new map's;
/// the voxel size and the rule fields the user set are checked against an existing map's.
struct MapRequest {
    std::optional<double> voxel_size_m;     ///< --voxel; a new map's default is 0.2 m
    double tile_size_m = 64.0;              ///< a new map's tile edge, metres
    std::optional<Eigen::Vector3d> origin;  ///< a new map's origin (georeferenced data)
    /// The first input file: when it is a LAS file and `origin` is unset, a new map's origin is
    /// the floor of its header's minimum (float32 at UTM scale would lose decimetres).
    std::filesystem::path georeference_from;
    RuleRequest rule;
};

/// @brief A map opened for writing, whether this call created it, and the rule to integrate with.
struct OpenedMap {
    store::MapStore map;
    bool created = false;
    integration::IntegrationConfig rule;
};

/// @brief The settings a new map gets from `request` (reads the LAS header when asked to).
/// @throw InvalidArgumentError for an invalid rule; the reader's errors for the LAS header.
[[nodiscard]] store::StoreSettings NewMapSettings(const MapRequest& request);

/// @brief Creates a map in `dir` with NewMapSettings(request), open for writing.
/// @throw InvalidArgumentError when `dir` holds a map already or for an invalid rule;
/// NewMapSettings' and the store's errors.
[[nodiscard]] OpenedMap CreateMap(const std::filesystem::path& dir, const MapRequest& request);

/// @brief Opens the map in `dir` for writing, or creates it when there is none (CreateMap).
/// @throw InvalidArgumentError when the request conflicts with an existing map (its voxel size
/// or a rule field, see ResolveRule); the store's errors (MapLockedError, FormatError, ...).
[[nodiscard]] OpenedMap OpenOrCreateMap(const std::filesystem::path& dir,
                                        const MapRequest& request);

}  // namespace strata::pipeline
