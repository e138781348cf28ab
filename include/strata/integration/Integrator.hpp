#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/core/Scan.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/integration/IntegrationConfig.hpp"

namespace strata::integration {

/// @brief Points of one scan that ended in one voxel with one class.
struct EndpointGroup {
    openvdb::Coord ijk;
    int32_t points = 0;
    core::SemanticClass label = core::SemanticClass::kUnknown;
    /// Sum over the group's points of (point - voxel centre), metres.
    Eigen::Vector3d offset_sum = Eigen::Vector3d::Zero();
};

/// @brief What one scan observed, before it touches a map (docs/integration.md, "Semantics"):
/// every voxel at most once, occupied winning over free.
struct ScanUpdate {
    openvdb::MaskTree::Ptr free;      ///< voxels the rays crossed, endpoints excluded; never null
    openvdb::MaskTree::Ptr occupied;  ///< endpoint voxels; never null
    /// The free voxels no ray crossed within its margin of its end (IntegrationConfig::
    /// crossed_margin_m, docs/dynamic.md); null when the config asks for none.
    openvdb::MaskTree::Ptr crossed;
    std::vector<EndpointGroup> endpoints;  ///< sorted by voxel then class
    size_t points = 0;                     ///< points in the scan
    size_t dropped = 0;                    ///< NaN/inf, or closer than min_range_m
    size_t clipped = 0;  ///< beyond max_range_m: cleared free space, recorded no hit
};

namespace detail {
struct Scratch;
}

/// @brief Where ComputeScanUpdate's time went, summed over the scans one workspace served.
struct UpdateSeconds {
    /// Points into the map frame, filtered and clipped; the scan's voxel box; endpoint voxels.
    double prepare = 0.0;
    /// Rays walked into bitmaps and turned into the free and occupied masks, endpoints grouped
    /// by voxel beside them; the update's size checked against the budget.
    double mark = 0.0;
};

/// @brief The working memory of ComputeScanUpdate, kept from one scan to the next (docs/
/// integration.md, "Where the whole command's time goes"): it grows to the largest scan it
/// served, so that a drive's scans neither allocate nor fault in their buffers afresh. One per
/// sequence of calls: a workspace is not shared by calls running at the same time.
class ScanWorkspace {
public:
    ScanWorkspace();
    ~ScanWorkspace();
    ScanWorkspace(ScanWorkspace&&) noexcept;
    ScanWorkspace& operator=(ScanWorkspace&&) noexcept;

    [[nodiscard]] const UpdateSeconds& seconds() const;

private:
    friend ScanUpdate ComputeScanUpdate(const core::Scan&, const core::VoxelMap&,
                                        const IntegrationConfig&, ScanWorkspace&);
    std::unique_ptr<detail::Scratch> scratch_;
};

/// @brief Computes the update of one scan against a map's voxel grid (the map is not modified).
/// Parallel over rays (TBB); the result does not depend on the number of threads, nor on the
/// scans `workspace` served before.
/// @throw InvalidArgumentError on an invalid config or scan; RefusedError when one scan would
/// grow the map by more than IntegrationConfig::max_update_bytes.
[[nodiscard]] ScanUpdate ComputeScanUpdate(const core::Scan& scan, const core::VoxelMap& map,
                                           const IntegrationConfig& config,
                                           ScanWorkspace& workspace);
/// @brief The same in a workspace of its own, given back when it returns.
[[nodiscard]] ScanUpdate ComputeScanUpdate(const core::Scan& scan, const core::VoxelMap& map,
                                           const IntegrationConfig& config);

/// @brief Applies an update: log-odds miss on free voxels, hit on occupied ones (clamped),
/// endpoint counts into `hits`, the running mean of endpoint positions into `point_mean`, label
/// votes into `label` / `label_weight`.
void ApplyScanUpdate(const ScanUpdate& update, core::VoxelMap& map,
                     const IntegrationConfig& config);

/// @brief Applies only the log-odds part of an update to one occupancy grid (a session's own
/// layer, for instance).
void ApplyOccupancyUpdate(const ScanUpdate& update, openvdb::FloatGrid& occupancy,
                          const IntegrationConfig& config);

/// @brief Integrates scans one by one into a map it does not own.
class Integrator {
public:
    /// @throw InvalidArgumentError on an invalid config.
    Integrator(core::VoxelMap& map, const IntegrationConfig& config);

    /// @brief ComputeScanUpdate then ApplyScanUpdate; returns the update it applied.
    ScanUpdate Integrate(const core::Scan& scan);

    [[nodiscard]] const IntegrationConfig& config() const { return config_; }
    /// @brief Where the scans' updates spent their time so far.
    [[nodiscard]] const UpdateSeconds& seconds() const { return workspace_.seconds(); }

private:
    core::VoxelMap& map_;
    IntegrationConfig config_;
    ScanWorkspace workspace_;
};

}  // namespace strata::integration
