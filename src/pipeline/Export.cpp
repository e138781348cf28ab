#include "strata/pipeline/Export.hpp"

#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>

#include "strata/core/Error.hpp"
#include "strata/io/AtomicFile.hpp"
#include "strata/io/OctomapExport.hpp"
#include "strata/io/PcdExport.hpp"
#include "strata/io/PlyExport.hpp"
#include "strata/io/PngExport.hpp"
#include "strata/io/PointCloudReaders.hpp"
#include "strata/io/VdbExport.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::pipeline {

void ExportOptions::Validate() const {
    if (!format.empty() && format != "vdb" && format != "bt" && format != "ot" && format != "ply" &&
        format != "pcd" && format != "png") {
        throw InvalidArgumentError("unknown export format '" + format +
                                   "' (use vdb, bt, ot, ply, pcd or png)");
    }
    if (pixels_per_voxel < 1) throw InvalidArgumentError("pixels_per_voxel must be >= 1");
    if (color != "auto" && color != "class" && color != "height") {
        throw InvalidArgumentError("unknown PNG colouring '" + color +
                                   "' (use auto, class or height)");
    }
}

std::string ExportFormat(const std::filesystem::path& out, const ExportOptions& options) {
    options.Validate();
    std::string format = options.format;
    if (format.empty()) {
        const std::string ext = out.extension().string();
        if (ext.size() < 2) {
            throw InvalidArgumentError(out.string() + ": no extension; give the format");
        }
        format = ext.substr(1);
        ExportOptions from_extension = options;
        from_extension.format = format;
        from_extension.Validate();
    }
    if ((format == "bt" || format == "ot") && out.extension() != "." + format) {
        throw InvalidArgumentError(out.string() + ": OctoMap files must end in ." + format);
    }
    if (!options.points.empty() && options.split) {
        throw InvalidArgumentError(out.string() +
                                   ": a cloud's kept points go to one file, not one per tile");
    }
    if (!options.points.empty() && format != "pcd") {
        throw InvalidArgumentError(out.string() + ": a cloud's kept points (" +
                                   options.points.string() + ") are written as pcd, not " + format);
    }
    return format;
}

namespace {

namespace fs = std::filesystem;

// A point cloud file's points in a map's frame, each with its voxel.
struct CloudInMap {
    core::Scan scan;
    std::vector<openvdb::Coord> voxels;
};

CloudInMap ReadCloud(const fs::path& file, const core::VoxelMap& frame) {
    io::ReadOptions read;
    read.origin = frame.origin;
    CloudInMap cloud{io::ReadPointCloud(file, read), {}};
    for (Eigen::Vector3d& p : cloud.scan.points) {
        p = cloud.scan.T_world_sensor * p;
        cloud.voxels.push_back(frame.WorldToVoxel(p));
    }
    return cloud;
}

// Which of `voxels[index[k]]` are occupied in `map`: one accessor, whose cache serves the run
// of neighbouring points a scan's order gives.
void MarkOccupied(const core::VoxelMap& map, const std::vector<openvdb::Coord>& voxels,
                  const std::vector<size_t>& index, std::vector<bool>& kept) {
    const openvdb::FloatGrid::ConstAccessor occupancy = map.occupancy->getConstAccessor();
    for (const size_t i : index) kept[i] = occupancy.getValue(voxels[i]) > 0.0F;
}

// The points `kept` marks, in the world frame, as WritePcd takes them.
void WriteKept(const CloudInMap& cloud, const std::vector<bool>& kept, const core::VoxelMap& frame,
               const fs::path& source, const fs::path& out) {
    io::PcdPoints pcd;
    pcd.origin_is_zero = frame.origin.isZero();
    for (size_t i = 0; i < cloud.scan.points.size(); ++i) {
        if (!kept[i]) continue;
        pcd.points.push_back(cloud.scan.points[i] + frame.origin);
        pcd.intensity.push_back(cloud.scan.intensity.empty() ? 0.0F : cloud.scan.intensity[i]);
    }
    io::WritePcd(
        pcd,
        "strata: the points of " + source.filename().string() + " whose voxel the map has occupied",
        out);
}

}  // namespace

std::string ExportMap(const core::VoxelMap& map, const std::filesystem::path& out,
                      const ExportOptions& options) {
    const std::string format = ExportFormat(out, options);
    if (format == "vdb") {
        io::WriteVdb(map, out);
    } else if (format == "bt" || format == "ot") {
        io::WriteOctomap(map, out);
    } else if (format == "ply") {
        io::WritePly(map, out);
    } else if (format == "pcd" && !options.points.empty()) {
        const CloudInMap cloud = ReadCloud(options.points, map);
        std::vector<size_t> all(cloud.voxels.size());
        for (size_t i = 0; i < all.size(); ++i) all[i] = i;
        std::vector<bool> kept(cloud.voxels.size(), false);
        MarkOccupied(map, cloud.voxels, all, kept);
        WriteKept(cloud, kept, map, options.points, out);
    } else if (format == "pcd") {
        io::WritePcd(
            map, [&](const std::function<void(const core::VoxelMap&)>& visit) { visit(map); }, out);
    } else {
        io::TopDownOptions png;
        png.pixels_per_voxel = options.pixels_per_voxel;
        // Unlabelled maps carry no class colours: show heights instead.
        png.color_by_height = options.color == "height" ||
                              (options.color == "auto" && map.label->activeVoxelCount() == 0);
        io::WriteTopDownPng(map, out, png);
    }
    return format;
}

namespace {

// `dir/city.vdb` -> `dir/city.X_Y.vdb`.
fs::path TileFile(const fs::path& out, const store::TileKey& key) {
    return out.parent_path() / (out.stem().string() + "." + std::to_string(key.x) + "_" +
                                std::to_string(key.y) + out.extension().string());
}

ExportResult ExportSplit(const store::MapStore& map, const store::TileReader& reader,
                         const fs::path& out, const ExportOptions& options,
                         const std::string& format) {
    ExportResult result{format, {}, 0};
    nlohmann::json index = {
        {"format", format},
        {"voxel_size_m", map.settings().voxel_size_m},
        {"tile_size_m", map.settings().tile_size_m()},
        {"origin",
         {map.settings().origin.x(), map.settings().origin.y(), map.settings().origin.z()}},
        {"tiles", nlohmann::json::array()}};
    ExportOptions one = options;
    one.format = format;
    for (const store::TileKey& key : reader.Tiles()) {
        const auto tile = reader.Fused(key);
        if (!tile) continue;
        ++result.tiles_read;
        const fs::path file = TileFile(out, key);
        (void)ExportMap(*tile, file, one);
        result.files.push_back(file);
        const double t = map.settings().tile_size_m();
        index["tiles"].push_back(
            {{"x", key.x},
             {"y", key.y},
             {"file", file.filename().string()},
             {"bounds_m", {key.x * t, key.y * t, (key.x + 1) * t, (key.y + 1) * t}}});
    }
    const fs::path index_file = out.parent_path() / (out.stem().string() + ".tiles.json");
    io::WriteFileAtomically(index_file, [&](std::ostream& os) { os << index.dump(2) << "\n"; });
    result.files.push_back(index_file);
    return result;
}

}  // namespace

ExportResult ExportStored(const store::MapStore& map, const store::Snapshot& snapshot,
                          const fs::path& out, const ExportOptions& options) {
    const std::string format = ExportFormat(out, options);
    // Nothing cached: each tile is read, written out and dropped.
    const store::TileReader reader(map, snapshot, 0);
    if (options.split) return ExportSplit(map, reader, out, options, format);
    if (format == "pcd" && !options.points.empty()) {
        // Each tile read once: the points grouped by tile, in the cloud's order within each.
        const core::VoxelMap frame = map.EmptyMap();
        const CloudInMap cloud = ReadCloud(options.points, frame);
        std::map<store::TileKey, std::vector<size_t>> by_tile;
        for (size_t i = 0; i < cloud.voxels.size(); ++i) {
            by_tile[map.settings().TileOf(cloud.voxels[i])].push_back(i);
        }
        std::vector<bool> kept(cloud.voxels.size(), false);
        ExportResult result{format, {out}, 0};
        for (const auto& [key, points] : by_tile) {
            const auto tile = reader.Fused(key);
            if (!tile) continue;  // no map there: nothing kept
            ++result.tiles_read;
            MarkOccupied(*tile, cloud.voxels, points, kept);
        }
        WriteKept(cloud, kept, frame, options.points, out);
        return result;
    }
    if (format == "ply" || format == "pcd") {
        ExportResult result{format, {out}, 0};
        const std::vector<store::TileKey> keys = reader.Tiles();
        const io::MapParts parts = [&](const std::function<void(const core::VoxelMap&)>& visit) {
            for (const store::TileKey& key : keys) {
                if (const auto tile = reader.Fused(key)) visit(*tile);
            }
        };
        format == "ply" ? io::WritePly(map.EmptyMap(), parts, out)
                        : io::WritePcd(map.EmptyMap(), parts, out);
        result.tiles_read = 2 * keys.size();
        return result;
    }
    const uint64_t bytes = map.Bytes(snapshot).fused_current;
    if (options.memory_budget_bytes > 0 && bytes > options.memory_budget_bytes) {
        throw RefusedError(
            map.dir().string() + ": its fused grids (" + std::to_string(bytes / 1000000) +
            " MB on disk) exceed the memory "
            "budget (" +
            std::to_string(options.memory_budget_bytes / 1000000) + " MB) for one " + format +
            " file; export one file per tile with "
            "--split, or raise --memory-budget");
    }
    (void)ExportMap(map.LoadMap(snapshot), out, options);
    return {format, {out}, snapshot.tiles.size()};
}

}  // namespace strata::pipeline
