#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <string>

#include "strata/core/Error.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::io {
std::string LowerExtension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
    return ext;
}

core::Scan ReadPointCloud(const std::filesystem::path& path, const ReadOptions& options) {
    const std::string ext = LowerExtension(path);
    if (ext == ".pcd") return ReadPcd(path, options);
    if (ext == ".ply") return ReadPly(path, options);
    if (ext == ".las" || ext == ".laz") return ReadLas(path, options);  // ReadLas refuses LAZ
    if (ext == ".bin") return ReadBin(path, options);  // KITTI .bin, nuScenes .pcd.bin
    // Any .bz2 is compressed text: the octomap example scan is scan.dat.bz2.
    if (ext == ".txt" || ext == ".xyz" || ext == ".csv" || ext == ".dat" || ext == ".bz2") {
        return ReadText(path, options);
    }
    throw InvalidArgumentError(path.string() + ": unknown point cloud extension '" + ext +
                               "' (expected .pcd, .ply, .las, .bin, .txt, .xyz, .csv, .dat or "
                               ".bz2)");
}

}  // namespace strata::io
