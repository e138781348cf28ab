// Raw float32 scans, the most common single-scan files: KITTI's velodyne .bin (x y z intensity)
// and nuScenes' .pcd.bin (x y z intensity ring), as OpenPCDet and mmdetection3d keep them.
#include <string>

#include "BinaryCursor.hpp"
#include "ScanBuilder.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::io {
namespace {

constexpr size_t kFloatBytes = 4;
constexpr int kKittiFields = 4;     // x y z intensity
constexpr int kNuScenesFields = 5;  // x y z intensity ring

bool EndsWithPcdBin(const std::filesystem::path& path) {
    std::string name = path.filename().string();
    for (char& c : name) c = (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
    const std::string suffix = ".pcd.bin";
    return name.size() > suffix.size() &&
           name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The float32 values per point: the option when given, 5 for nuScenes' `.pcd.bin` names, else
// the one of 4 and 5 whose record size divides the file size.
int FieldCount(const std::filesystem::path& path, size_t bytes, int option) {
    const std::string file = path.string();
    const std::string size = std::to_string(bytes) + " bytes";
    if (option != 0 && option != kKittiFields && option != kNuScenesFields) {
        throw InvalidArgumentError(
            file + ": " + std::to_string(option) +
            " float32 fields per point asked for; .bin scans have 4 "
            "(KITTI: x y z intensity) or 5 (nuScenes: x y z intensity ring)");
    }
    const int fields = option != 0 ? option : EndsWithPcdBin(path) ? kNuScenesFields : 0;
    if (fields != 0) {
        if (bytes % (fields * kFloatBytes) != 0) {
            throw FormatError(file + ": size " + size + " is not a multiple of " +
                              std::to_string(fields * kFloatBytes) + " (N points x " +
                              std::to_string(fields) + " float32): truncated, or not " +
                              std::to_string(fields) + " fields per point");
        }
        return fields;
    }
    const bool kitti = bytes % (kKittiFields * kFloatBytes) == 0;
    const bool nuscenes = bytes % (kNuScenesFields * kFloatBytes) == 0;
    if (kitti != nuscenes) return kitti ? kKittiFields : kNuScenesFields;
    throw FormatError(file + ": size " + size + (kitti ? " fits both" : " fits neither") +
                      " 4 float32 per point (KITTI .bin: x y z intensity) and 5 (nuScenes "
                      ".pcd.bin: x y z intensity ring)" +
                      (kitti ? ": give the field count (--bin-fields 4 or 5)"
                             : ": truncated, or not a raw float32 scan"));
}

}  // namespace

core::Scan ReadBin(const std::filesystem::path& path, const ReadOptions& options) {
    const std::vector<uint8_t> bytes = detail::ReadFileBytes(path);
    detail::ScanBuilder builder(path, options, detail::KittiMapping(),
                                detail::PointLayout{/*has_intensity=*/true, false, false});
    if (bytes.empty()) return builder.Finish();  // no points, as an empty text file
    const size_t fields = static_cast<size_t>(FieldCount(path, bytes.size(), options.bin_fields));
    const size_t n = bytes.size() / (fields * kFloatBytes);
    builder.Reserve(n);
    const uint8_t* p = bytes.data();
    for (size_t i = 0; i < n; ++i, p += fields * kFloatBytes) {
        const float x = detail::LoadScalar<float>(p, false);
        const float y = detail::LoadScalar<float>(p + kFloatBytes, false);
        const float z = detail::LoadScalar<float>(p + 2 * kFloatBytes, false);
        builder.Add(x, y, z, detail::LoadScalar<float>(p + 3 * kFloatBytes, false), 0);
    }
    return builder.Finish();
}

}  // namespace strata::io
