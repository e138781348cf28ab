#include "Analyses.hpp"

#include <functional>
#include <map>

#include "Arrays.hpp"
#include "strata/core/Error.hpp"
#include "strata/walls/WallReport.hpp"

namespace strata::python {

namespace {

template <typename T>
std::function<void(walls::WallConfig&, const py::handle&)> Field(T walls::WallConfig::*member) {
    return [member](walls::WallConfig& c, const py::handle& v) { c.*member = v.cast<T>(); };
}

}  // namespace

walls::WallConfig WallConfigFrom(const py::kwargs& options) {
    using C = walls::WallConfig;
    static const std::map<std::string, std::function<void(C&, const py::handle&)>> fields = {
        {"window_m", Field(&C::window_m)},
        {"min_wall_height_m", Field(&C::min_wall_height_m)},
        {"min_window_points", Field(&C::min_window_points)},
        {"ground_clearance_m", Field(&C::ground_clearance_m)},
        {"dbscan_eps_voxels", Field(&C::dbscan_eps_voxels)},
        {"dbscan_min_points", Field(&C::dbscan_min_points)},
        {"kmeans_divisor", Field(&C::kmeans_divisor)},
        {"ransac_threshold_m", Field(&C::ransac_threshold_m)},
        {"ransac_iterations", Field(&C::ransac_iterations)},
        {"min_part_voxels", Field(&C::min_part_voxels)},
        {"min_inlier_fraction", Field(&C::min_inlier_fraction)},
        {"min_eigen_ratio", Field(&C::min_eigen_ratio)},
        {"min_slant_deg", Field(&C::min_slant_deg)},
        {"min_part_height_m", Field(&C::min_part_height_m)},
        {"min_part_length_m", Field(&C::min_part_length_m)},
        {"merge_angle_deg", Field(&C::merge_angle_deg)},
        {"merge_gap_m", Field(&C::merge_gap_m)},
        {"merge_support", Field(&C::merge_support)},
        {"refine", Field(&C::refine)},
        {"min_wall_length_m", Field(&C::min_wall_length_m)},
        {"seed", Field(&C::seed)},
        {"level_to_ground", Field(&C::level_to_ground)},
        {"use_point_means", Field(&C::use_point_means)},
    };
    C config;
    for (const auto& [key, value] : options) {
        const std::string name = key.cast<std::string>();
        const auto field = fields.find(name);
        if (field == fields.end()) {
            std::string known;
            for (const auto& f : fields) known += (known.empty() ? "" : ", ") + f.first;
            throw InvalidArgumentError("unknown wall option '" + name + "' (options: " + known +
                                       ")");
        }
        try {
            field->second(config, value);
        } catch (const py::cast_error&) {
            throw InvalidArgumentError("wall option '" + name + "' has the wrong type");
        }
    }
    config.Validate();
    return config;
}

py::object ParseJson(const std::string& text) {
    return py::module_::import("json").attr("loads")(text);
}

py::dict WallsReport(const core::VoxelMap& map, const walls::WallResult& result,
                     const walls::WallConfig& config) {
    py::dict report = ParseJson(walls::WallsJson(result, config, map.origin));
    openvdb::FloatGrid::Ptr slants;
    openvdb::Int32Grid::Ptr ids;
    for (const openvdb::GridBase::Ptr& grid : walls::WallGrids(result)) {
        if (grid->getName() == walls::product_names::kSlantDeg) {
            slants = openvdb::gridPtrCast<openvdb::FloatGrid>(grid);
        } else if (grid->getName() == walls::product_names::kWallId) {
            ids = openvdb::gridPtrCast<openvdb::Int32Grid>(grid);
        }
    }
    std::vector<double> center;
    std::vector<float> slant;
    std::vector<int32_t> id;
    if (slants && ids) {
        const auto wall_of = ids->getConstAccessor();
        for (auto it = slants->cbeginValueOn(); it; ++it) {
            const Eigen::Vector3d c = map.VoxelCenter(it.getCoord());
            center.insert(center.end(), {c.x(), c.y(), c.z()});
            slant.push_back(*it);
            id.push_back(wall_of.getValue(it.getCoord()));
        }
    }
    const auto n = static_cast<py::ssize_t>(slant.size());
    py::dict voxels;
    voxels["center"] = ToArray(std::move(center), {n, 3});
    voxels["slant_deg"] = ToArray(std::move(slant), {n});
    voxels["wall_id"] = ToArray(std::move(id), {n});
    report["voxels"] = voxels;
    return report;
}

}  // namespace strata::python
