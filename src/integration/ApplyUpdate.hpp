#pragma once
// Private to the integrator: step 3, writing a scan's update into the grids of a map.

#include "strata/core/VoxelMap.hpp"
#include "strata/integration/Integrator.hpp"

namespace strata::integration::detail {

/// Log-odds miss on free voxels, hit on occupied ones, clamped, leaf by leaf in parallel.
void ApplyOccupancy(const ScanUpdate& update, openvdb::FloatGrid& occupancy,
                    const IntegrationConfig& config);

/// Endpoint counts into `hits`; label votes into `label` / `label_weight`.
void ApplyEndpoints(const ScanUpdate& update, core::VoxelMap& map, const IntegrationConfig& config);

}  // namespace strata::integration::detail
