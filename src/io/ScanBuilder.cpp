#include "ScanBuilder.hpp"

#include <utility>

namespace strata::io::detail {

const core::LabelMapping& KittiMapping() {
    static const core::LabelMapping mapping = core::LabelMapping::SemanticKitti();
    return mapping;
}

const core::LabelMapping& LasMapping() {
    static const core::LabelMapping mapping = core::LabelMapping::Las();
    return mapping;
}

ScanBuilder::ScanBuilder(const std::filesystem::path& path, const ReadOptions& options,
                         const core::LabelMapping& default_mapping, const PointLayout& layout)
    : origin_(options.origin),
      mapping_(options.mapping != nullptr ? *options.mapping : default_mapping),
      layout_(layout) {
    scan_.source = path.string();
}

void ScanBuilder::Reserve(size_t n) {
    scan_.points.reserve(n);
    if (layout_.has_intensity) scan_.intensity.reserve(n);
    if (layout_.has_label) {
        scan_.labels.reserve(n);
        scan_.instances.reserve(n);
    }
}

core::Scan ScanBuilder::Finish() {
    if (!any_instance_) {
        scan_.instances.clear();
        scan_.instances.shrink_to_fit();
    }
    return std::move(scan_);
}

}  // namespace strata::io::detail
