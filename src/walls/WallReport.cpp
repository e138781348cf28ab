#include "strata/walls/WallReport.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "strata/io/Image.hpp"

namespace strata::walls {
namespace {

constexpr const char* kConvention =
    "slant_deg = arccos(|g . n| / (|g| |n|)), g = (0, 0, -1): 90 = vertical, 0 = horizontal; "
    "lean_azimuth_deg: direction the top leans to, counter-clockwise from +x";

nlohmann::json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

double Round(double v, double unit) { return std::round(v / unit) * unit; }

}  // namespace

openvdb::GridPtrVec WallGrids(const WallResult& result) {
    const auto transform = core::VoxelMap::MakeTransform(result.voxel_size);
    auto slant = openvdb::FloatGrid::create(0.0f);
    auto id = openvdb::Int32Grid::create(0);
    auto sa = slant->getAccessor();
    auto ia = id->getAccessor();
    // A voxel on two walls (at a corner) keeps the larger wall: walls come largest first.
    for (const Wall& w : result.walls) {
        for (const openvdb::Coord& c : w.voxels) {
            if (ia.isValueOn(c)) continue;
            sa.setValue(c, static_cast<float>(w.slant_deg));
            ia.setValue(c, w.id);
        }
    }
    slant->setName(product_names::kSlantDeg);
    slant->insertMeta("units", openvdb::StringMetadata("deg"));
    slant->insertMeta("convention", openvdb::StringMetadata(kConvention));
    id->setName(product_names::kWallId);
    id->insertMeta("units", openvdb::StringMetadata("wall id (strata walls --json)"));
    openvdb::GridPtrVec grids{slant, id};
    for (auto& g : grids) {
        g->setTransform(transform->copy());
        g->setGridClass(openvdb::GRID_UNKNOWN);
    }
    return grids;
}

std::string WallsJson(const WallResult& result, const WallConfig& config,
                      const Eigen::Vector3d& origin) {
    nlohmann::json walls = nlohmann::json::array();
    for (const Wall& w : result.walls) {
        walls.push_back({{"id", w.id},
                         {"slant_deg", Round(w.slant_deg, 1e-4)},
                         {"slant_to_ground_deg", Round(w.slant_to_ground_deg, 1e-4)},
                         {"centroid", Vec(w.centroid)},
                         {"normal", Vec(w.normal)},
                         {"d", w.d},
                         {"inliers", w.inliers},
                         {"area_m2", Round(w.area_m2, 1e-3)},
                         {"rms_m", Round(w.rms_m, 1e-5)},
                         {"uncertainty_deg", Round(w.uncertainty_deg, 1e-4)},
                         {"lean_azimuth_deg", Round(w.lean_azimuth_deg, 1e-3)},
                         {"length_m", Round(w.length_m, 1e-3)},
                         {"height_m", Round(w.height_m, 1e-3)},
                         {"parts", w.parts},
                         {"eigen_ratio", w.eigen_ratio}});
    }
    std::map<std::string, size_t> verdicts;
    for (const WallPart& p : result.parts) ++verdicts[VerdictName(p.verdict)];
    const WallStats& s = result.stats;
    nlohmann::json j;
    j["walls"] = walls;
    j["voxel_size"] = result.voxel_size;
    j["origin"] = Vec(origin);
    j["slant_convention"] = kConvention;
    j["up"] = Vec(result.up);
    j["ground"] = {{"normal", Vec(result.ground.normal)},
                   {"tilt_deg", Round(result.ground.tilt_deg, 1e-4)},
                   {"columns", result.ground.columns}};
    j["stats"] = {{"occupied_columns", s.occupied_columns},
                  {"voting_columns", s.voting_columns},
                  {"candidate_voxels", s.candidate_voxels},
                  {"clusters", s.clusters},
                  {"noise_voxels", s.noise_voxels},
                  {"parts", result.parts.size()},
                  {"part_verdicts", verdicts},
                  {"seconds",
                   {{"columns", s.seconds_columns},
                    {"clustering", s.seconds_clustering},
                    {"fitting", s.seconds_fitting}}}};
    j["config"] = {{"window_m", config.window_m},
                   {"min_wall_height_m", config.min_wall_height_m},
                   {"min_window_points", config.min_window_points},
                   {"ground_clearance_m", config.ground_clearance_m},
                   {"dbscan_eps_voxels", config.dbscan_eps_voxels},
                   {"dbscan_min_points", config.dbscan_min_points},
                   {"kmeans_divisor", config.kmeans_divisor},
                   {"ransac_threshold_m", config.ransac_threshold_m},
                   {"min_inlier_fraction", config.min_inlier_fraction},
                   {"min_eigen_ratio", config.min_eigen_ratio},
                   {"min_slant_deg", config.min_slant_deg},
                   {"min_part_height_m", config.min_part_height_m},
                   {"min_part_length_m", config.min_part_length_m},
                   {"refine", config.refine},
                   {"level_to_ground", config.level_to_ground}};
    return j.dump(2) + "\n";
}

std::string WallsCsv(const WallResult& result) {
    std::ostringstream os;
    os << std::setprecision(10);
    os << "id,slant_deg,uncertainty_deg,lean_azimuth_deg,centroid_x,centroid_y,centroid_z,"
          "normal_x,normal_y,normal_z,inliers,area_m2,rms_m,length_m,height_m\n";
    for (const Wall& w : result.walls) {
        os << w.id << ',' << w.slant_deg << ',' << w.uncertainty_deg << ',' << w.lean_azimuth_deg
           << ',' << w.centroid.x() << ',' << w.centroid.y() << ',' << w.centroid.z() << ','
           << w.normal.x() << ',' << w.normal.y() << ',' << w.normal.z() << ',' << w.inliers << ','
           << w.area_m2 << ',' << w.rms_m << ',' << w.length_m << ',' << w.height_m << '\n';
    }
    return os.str();
}

core::Rgb SlantColor(double slant_deg, double max_deviation_deg) {
    // Blue (vertical) -> green -> yellow -> red (max deviation or more).
    static const std::vector<core::Rgb> kStops = {
        {40, 110, 255}, {40, 200, 80}, {255, 220, 0}, {230, 30, 30}};
    return io::Ramp(kStops, (90.0 - slant_deg) / max_deviation_deg);
}

void WriteWallsPng(const core::VoxelMap& map, const WallResult& result,
                   const std::filesystem::path& path, int max_pixels) {
    // Occupied voxels per column: the grey background.
    std::map<std::pair<int, int>, int> column;
    openvdb::CoordBBox box;
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it <= 0.0f || !it.isVoxelValue()) continue;
        const openvdb::Coord c = it.getCoord();
        ++column[{c.x(), c.y()}];
        box.expand(c);
    }
    if (box.empty()) box = openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(0));
    const openvdb::Coord extent = box.extents();
    const int longest = std::max(extent.x(), extent.y());
    constexpr int kMinPixels = 1400;
    const int voxels_per_pixel = std::max(1, (longest + max_pixels - 1) / max_pixels);
    const int pixels_per_voxel =
        voxels_per_pixel > 1
            ? 1
            : std::max(1, std::min(8, (kMinPixels + longest - 1) / std::max(1, longest)));
    const int width = (extent.x() + voxels_per_pixel - 1) / voxels_per_pixel * pixels_per_voxel;
    const int legend_height = 40;
    const int height =
        (extent.y() + voxels_per_pixel - 1) / voxels_per_pixel * pixels_per_voxel + legend_height;
    io::RgbImage image(std::max(width, 640), height, {255, 255, 255});
    const int map_height = height - legend_height;
    const auto cell = [&](int i, int j, core::Rgb color) {
        const int x = (i - box.min().x()) / voxels_per_pixel * pixels_per_voxel;
        const int y = map_height - ((j - box.min().y()) / voxels_per_pixel + 1) * pixels_per_voxel;
        image.FillRect(x, y, pixels_per_voxel, pixels_per_voxel, color);
    };
    for (const auto& [ij, n] : column) {
        const auto g = static_cast<uint8_t>(std::clamp(235 - 12 * (n - 1), 90, 235));
        cell(ij.first, ij.second, {g, g, g});
    }
    // Walls over the background; the most tilted wall of a column wins.
    std::map<std::pair<int, int>, double> slant;
    for (const Wall& w : result.walls) {
        for (const openvdb::Coord& c : w.voxels) {
            const auto key = std::pair{c.x(), c.y()};
            const auto it = slant.find(key);
            if (it == slant.end() || w.slant_deg < it->second) slant[key] = w.slant_deg;
        }
    }
    for (const auto& [ij, deg] : slant) cell(ij.first, ij.second, SlantColor(deg));
    // Legend: a dark strip with patches for 90 .. 85 degrees on the right (the scale bar takes
    // the bottom-left corner).
    image.FillRect(0, map_height, image.width(), legend_height, {24, 24, 24});
    const int legend_x = image.width() - 6 * 65 - 10;
    for (int k = 0; k <= 5; ++k) {
        const int x = legend_x + k * 65;
        image.FillRect(x, map_height + 12, 18, 18, SlantColor(90.0 - k));
        io::DrawLabel(image, x + 24, map_height + 16, std::to_string(90 - k), 2);
    }
    io::DrawScaleBar(image, map.voxel_size * voxels_per_pixel / pixels_per_voxel);
    io::WritePng(image, path);
}

}  // namespace strata::walls
