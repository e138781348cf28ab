#pragma once

// Private to io: turns decoded point records into a Scan the same way for every file format
// (origin subtraction, invalid point filter, label mapping and instance split).

#include <cmath>
#include <cstdint>
#include <filesystem>

#include "strata/core/Labels.hpp"
#include "strata/core/Scan.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::io::detail {

/// @brief SemanticKITTI and LAS mappings, built once (thread-safe static initialisation).
[[nodiscard]] const core::LabelMapping& KittiMapping();
[[nodiscard]] const core::LabelMapping& LasMapping();

/// @brief A label decoded as a number (PCD, PLY) to a raw uint32 id; NaN and negatives give 0.
[[nodiscard]] inline uint32_t ToRawLabel(double value) {
    if (!(value > 0.0)) return 0;
    return value >= 4294967295.0 ? 0xFFFFFFFFu : static_cast<uint32_t>(value);
}

/// @brief Which optional attributes a file has, and whether (0,0,0) marks a missing return.
struct PointLayout {
    bool has_intensity = false;
    bool has_label = false;
    bool drop_zero = false;
};

/// @brief Collects points of one file into a Scan at the identity pose.
class ScanBuilder {
public:
    /// @param default_mapping used when options.mapping is nullptr; must outlive the builder.
    ScanBuilder(const std::filesystem::path& path, const ReadOptions& options,
                const core::LabelMapping& default_mapping, const PointLayout& layout);

    /// @brief Reserves for `n` points; callers pass a count already checked against the file.
    void Reserve(size_t n);

    /// @brief Adds one point in file coordinates. Non-finite points, and (0,0,0) when the
    /// layout says so, are dropped. `raw_label`: low 16 bits class, high 16 bits instance.
    void Add(double x, double y, double z, float intensity, uint32_t raw_label) {
        if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return;
        if (layout_.drop_zero && x == 0.0 && y == 0.0 && z == 0.0) return;
        scan_.points.emplace_back(x - origin_.x(), y - origin_.y(), z - origin_.z());
        if (layout_.has_intensity) scan_.intensity.push_back(intensity);
        if (layout_.has_label) {
            scan_.labels.push_back(mapping_.Map(raw_label & 0xFFFFu));
            scan_.instances.push_back(static_cast<uint16_t>(raw_label >> 16));
            any_instance_ = any_instance_ || (raw_label >> 16) != 0;
        }
    }

    /// @brief Returns the scan; `instances` is emptied when every instance id is 0.
    [[nodiscard]] core::Scan Finish();

private:
    core::Scan scan_;
    Eigen::Vector3d origin_;
    const core::LabelMapping& mapping_;
    PointLayout layout_;
    bool any_instance_ = false;
};

}  // namespace strata::io::detail
