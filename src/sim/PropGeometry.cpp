#include <cmath>
#include <type_traits>

#include "MeshBuilders.hpp"
#include "ObjectGeometry.hpp"
#include "WallGeometry.hpp"
#include "strata/sim/KittiIds.hpp"

namespace strata::sim::detail {
namespace {

Mesh Labelled(Mesh mesh, const ObjectSpec& object, uint16_t label) {
    mesh.label = label;
    mesh.instance = static_cast<uint16_t>(object.id);
    mesh.reflectivity = object.reflectivity;
    return mesh;
}

Mesh BoxMesh(const BoxSpec& box) {
    Mesh mesh = MakeBox(box.size, box.bottom);
    TransformMesh(mesh, YawPose(box.center, DegToRad(box.yaw_deg)));
    return mesh;
}

}  // namespace

std::vector<Mesh> BuildPropMeshes(const ObjectSpec& object) {
    std::vector<Mesh> meshes;
    if (const auto* box = std::get_if<BoxSpec>(&object.shape)) {
        meshes.push_back(Labelled(BoxMesh(*box), object, object.label));
    } else if (const auto* pole = std::get_if<PoleSpec>(&object.shape)) {
        meshes.push_back(Labelled(
            MakeCylinder(pole->base, Eigen::Vector3d::UnitZ(), pole->radius_m, pole->height_m, 8),
            object, object.label));
        if (pole->sign) {
            // A square plate facing +x just below the top.
            const Eigen::Vector3d centre =
                pole->base + Eigen::Vector3d(pole->radius_m + 0.03, 0, pole->height_m - 0.5);
            meshes.push_back(Labelled(BoxMesh({centre, {0.04, 0.6, 0.6}, 0.0, true}), object,
                                      kitti::kTrafficSign));
        }
    } else if (const auto* stairs = std::get_if<StairsSpec>(&object.shape)) {
        // Solid steps: step i is a box from the floor to its tread, run_m deep.
        Mesh mesh;
        const double yaw = DegToRad(stairs->yaw_deg);
        const Eigen::Vector3d dir(std::cos(yaw), std::sin(yaw), 0.0);
        for (int i = 0; i < stairs->steps; ++i) {
            const double top = (i + 1) * stairs->rise_m;
            const Eigen::Vector3d centre =
                stairs->start + (i + 0.5) * stairs->run_m * dir + Eigen::Vector3d(0, 0, 0.5 * top);
            mesh.Append(
                BoxMesh({centre, {stairs->run_m, stairs->width_m, top}, stairs->yaw_deg, false}));
        }
        meshes.push_back(Labelled(std::move(mesh), object, object.label));
    }
    return meshes;
}

std::vector<Mesh> BuildObjectMeshes(const ObjectSpec& object, uint64_t scene_seed) {
    std::vector<Mesh> meshes = std::visit(
        [&](const auto& shape) -> std::vector<Mesh> {
            using T = std::decay_t<decltype(shape)>;
            if constexpr (std::is_same_v<T, SlabSpec>) {
                return BuildSlabMeshes(object, shape);
            } else if constexpr (std::is_same_v<T, WallSpec>) {
                return BuildWallMeshes(object, shape);
            } else if constexpr (std::is_same_v<T, VehicleSpec>) {
                return {BuildVehicleMesh(object, shape)};
            } else if constexpr (std::is_same_v<T, PlantSpec>) {
                return BuildPlantMeshes(object, shape, scene_seed);
            } else {
                return BuildPropMeshes(object);
            }
        },
        object.shape);
    const bool solid = !std::holds_alternative<SlabSpec>(object.shape) &&
                       !std::holds_alternative<PlantSpec>(object.shape);
    for (Mesh& m : meshes) m.solid = solid;
    return meshes;
}

BoxTruth ObjectBox(const ObjectSpec& object) {
    BoxTruth box;
    box.id = object.id;
    box.name = object.name;
    box.type = kitti::Name(object.label);
    if (const auto* v = std::get_if<VehicleSpec>(&object.shape)) {
        box.type = v->type;
        box.center = v->center + Eigen::Vector3d(0, 0, 0.5 * v->size.z());
        box.size = v->size;
        box.yaw_deg = v->yaw_deg;
    } else if (const auto* b = std::get_if<BoxSpec>(&object.shape)) {
        box.center = b->center;
        box.size = b->size;
        box.yaw_deg = b->yaw_deg;
    } else if (const auto* p = std::get_if<PlantSpec>(&object.shape)) {
        const Eigen::Vector3d r = p->crown_radii;
        const double top = p->crown_center_height_m + r.z();
        box.center = p->base + Eigen::Vector3d(0, 0, 0.5 * top);
        box.size = Eigen::Vector3d(2 * r.x(), 2 * r.y(), top);
    } else if (const auto* w = std::get_if<WallSpec>(&object.shape)) {
        // Box along the first segment, over the whole base path.
        const WallFrame frame(*w);
        const Eigen::Vector2d d = frame.Direction(0.0);
        box.center = 0.5 * (frame.At(0, 0.5 * w->height_m, 0.5 * w->thickness_m) +
                            frame.At(frame.length(), 0.5 * w->height_m, 0.5 * w->thickness_m));
        box.size = Eigen::Vector3d(frame.length(), w->thickness_m, w->height_m);
        box.yaw_deg = RadToDeg(std::atan2(d.y(), d.x()));
    } else if (const auto* pole = std::get_if<PoleSpec>(&object.shape)) {
        box.center = pole->base + Eigen::Vector3d(0, 0, 0.5 * pole->height_m);
        box.size = Eigen::Vector3d(2 * pole->radius_m, 2 * pole->radius_m, pole->height_m);
    }
    return box;
}

}  // namespace strata::sim::detail
