#include "strata/dynamic/DynamicPicture.hpp"

#include <algorithm>

#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/io/PngExport.hpp"

namespace strata::dynamic {

void WriteDynamicPng(const core::VoxelMap& raw, const core::VoxelMap& static_map,
                     const DynamicResult& result, const std::filesystem::path& path) {
    // Before: the raw map with the removed voxels drawn occupied, in the dynamic class's colour.
    core::VoxelMap before = raw.DeepCopy();
    const auto dynamic = static_cast<int32_t>(core::SemanticClass::kDynamic);
    for (auto on = result.removed->tree().cbeginValueOn(); on; ++on) {
        before.occupancy->tree().setValueOn(on.getCoord(), 1.0F);
        before.label->tree().setValueOn(on.getCoord(), dynamic);
    }
    io::TopDownOptions options;
    const io::TopDownImage left = io::RenderTopDown(before, options);
    const io::TopDownImage right = io::RenderTopDown(static_map, options);
    // Side by side, 8 pixels apart.
    const int gap = 8;
    io::RgbImage both(left.image.width() + gap + right.image.width(),
                      std::max(left.image.height(), right.image.height()), {255, 255, 255});
    for (int y = 0; y < left.image.height(); ++y) {
        for (int x = 0; x < left.image.width(); ++x) both.Set(x, y, left.image.At(x, y));
    }
    for (int y = 0; y < right.image.height(); ++y) {
        for (int x = 0; x < right.image.width(); ++x) {
            both.Set(left.image.width() + gap + x, y, right.image.At(x, y));
        }
    }
    io::WritePng(both, path);
}

}  // namespace strata::dynamic
