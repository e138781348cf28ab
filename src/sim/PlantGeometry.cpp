#include <cmath>

#include "MeshBuilders.hpp"
#include "ObjectGeometry.hpp"
#include "Rng.hpp"
#include "strata/sim/KittiIds.hpp"

namespace strata::sim::detail {

std::vector<Mesh> BuildPlantMeshes(const ObjectSpec& object, const PlantSpec& plant,
                                   uint64_t scene_seed) {
    std::vector<Mesh> meshes;
    const Eigen::Vector3d centre = plant.base + Eigen::Vector3d(0, 0, plant.crown_center_height_m);
    const Eigen::Vector3d& radii = plant.crown_radii;
    if (plant.tree) {
        // Trunk from the ground into the middle of the crown.
        Mesh trunk = MakeCylinder(plant.base, Eigen::Vector3d::UnitZ(), plant.trunk_radius_m,
                                  plant.crown_center_height_m, 10);
        trunk.label = kitti::kTrunk;
        trunk.instance = static_cast<uint16_t>(object.id);
        trunk.reflectivity = 0.35F;
        meshes.push_back(std::move(trunk));
    }
    // Crown: small randomly oriented leaf triangles filling an ellipsoid. Rays pass between
    // them, so vegetation is porous and noisy as real foliage is. The leaf positions depend on
    // the scene seed and the object id only; a grown plant (larger radii) keeps its seed.
    Rng rng(HashKey(scene_seed, static_cast<uint64_t>(object.id), 0x1eaf));
    const double volume = 4.0 / 3.0 * M_PI * radii.x() * radii.y() * radii.z();
    const auto leaves = static_cast<size_t>(std::ceil(volume * plant.leaves_per_m3));
    Mesh crown;
    crown.vertices.reserve(3 * leaves);
    for (size_t i = 0; i < leaves; ++i) {
        // One draw per statement, z first: the order in which function arguments are evaluated
        // is unspecified (gcc goes right to left, clang left to right), and a scene must not
        // depend on the compiler. z, y, x is the order the gcc builds always had.
        Eigen::Vector3d q;
        do {
            q.z() = rng.Uniform(-1, 1);
            q.y() = rng.Uniform(-1, 1);
            q.x() = rng.Uniform(-1, 1);
        } while (q.squaredNorm() > 1.0);
        const Eigen::Vector3d p = centre + q.cwiseProduct(radii);
        Eigen::Vector3d n;
        n.z() = rng.Normal();
        n.y() = rng.Normal();
        n.x() = rng.Normal();
        n.normalize();
        const Eigen::Vector3d e1 = n.unitOrthogonal();
        const Eigen::Vector3d e2 = n.cross(e1);
        const double s = plant.leaf_size_m * rng.Uniform(0.6, 1.4);
        const double a0 = rng.Uniform(0, 2 * M_PI);
        Eigen::Vector3d v[3];
        for (int k = 0; k < 3; ++k) {
            const double a = a0 + k * 2.0 * M_PI / 3.0;
            v[k] = p + 0.5 * s * (std::cos(a) * e1 + std::sin(a) * e2);
        }
        AddTriangle(crown, v[0], v[1], v[2]);
    }
    crown.label = object.label;
    crown.instance = static_cast<uint16_t>(object.id);
    crown.reflectivity = object.reflectivity;
    meshes.push_back(std::move(crown));
    return meshes;
}

}  // namespace strata::sim::detail
