#pragma once
// `strata localize` and Python's Map.localize: one scan localized in the slice
// l1 < z - z_k < l2 of storey k of a stacked map (docs/registration.md).

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "strata/pipeline/Alignment.hpp"
#include "strata/registration/Floors.hpp"

namespace strata::pipeline {

/// @brief Where and how a scan is localized.
struct LocalizeOptions {
    int floor = 0;  ///< the storey's index (as `strata stack` recorded it)
    /// The storey with its floor and ceiling, none of the others.
    registration::FloorSlice slice = {-0.2, 3.1};
    std::optional<Eigen::Isometry3d> guess;  ///< T_map_scan; default: the storey's frame
    /// Range limits of the scan's points and the registration (LocalizationRegistration).
    AlignOptions align = DefaultAlign();

    /// @brief Throws InvalidArgumentError naming the first bad field.
    void Validate() const;
    /// @brief AlignOptions with min_range_m 0.5 and LocalizationRegistration().
    [[nodiscard]] static AlignOptions DefaultAlign();
};

/// @brief The scan's pose in the storey's slice (whether or not it was accepted).
struct Localization {
    MapAlignment alignment;  ///< T_map_source: scan frame -> map frame
    int floor = 0;
    double z_m = 0.0;  ///< the storey's floor surface height
};

/// @brief Localizes a scan (points in its sensor frame) in storey `options.floor`. A
/// registration that does not converge is returned (RequireAccepted refuses it), not thrown.
/// The map is only read.
/// @throw InvalidArgumentError for bad options or a storey not recorded;
/// RefusedError when the slice holds no surface.
[[nodiscard]] Localization Localize(const store::MapStore& map,
                                    const std::vector<Eigen::Vector3d>& points,
                                    const LocalizeOptions& options);

/// @brief Localize with the scan read from `scan_file` (ReadScanFile), read once the storey is
/// found, so a bad storey is reported before a bad file.
[[nodiscard]] Localization LocalizeFile(const store::MapStore& map,
                                        const std::filesystem::path& scan_file,
                                        const LocalizeOptions& options);

/// @brief What `strata localize --json` prints: AlignmentJson with floor and z_m.
[[nodiscard]] nlohmann::json LocalizationJson(const Localization& l);

}  // namespace strata::pipeline
