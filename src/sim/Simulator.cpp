#include "strata/sim/Simulator.hpp"

#include "EmbreeScene.hpp"
#include "ObjectGeometry.hpp"
#include "strata/sim/KittiIds.hpp"

namespace strata::sim {

Simulator::Simulator(const Scene& scene) : embree_(std::make_unique<EmbreeScene>(scene.meshes)) {
    const core::LabelMapping mapping = core::LabelMapping::SemanticKitti();
    for (const Mesh& m : scene.meshes) {
        classes_.push_back(mapping.Map(m.label));
        labels_.push_back(m.label);
        instances_.push_back(m.instance);
        reflectivity_.push_back(m.reflectivity);
    }
    actors_ = scene.actors;
    for (const ActorSpec& a : actors_) {
        a.Validate();
        actor_meshes_.push_back(detail::BuildActorMesh(a));
        const uint16_t standing = ActorLabel(a.type, false), moving = ActorLabel(a.type, true);
        actor_labels_.push_back({standing, moving});
        actor_classes_.push_back({mapping.Map(standing), mapping.Map(moving)});
    }
}

Simulator::~Simulator() = default;
Simulator::Simulator(Simulator&&) noexcept = default;
Simulator& Simulator::operator=(Simulator&&) noexcept = default;

SimulatedScan Simulator::SimulateScan(const Eigen::Isometry3d& T_world_sensor,
                                      const SensorModel& sensor, uint64_t seed) const {
    SweepRequest request;
    request.T_world_sensor = T_world_sensor;
    request.seed = seed;
    return SimulateSweep(request, sensor);
}

std::optional<RayHit> Simulator::CastRay(const Eigen::Vector3d& origin,
                                         const Eigen::Vector3d& direction,
                                         double max_range_m) const {
    const Eigen::Vector3d d = direction.normalized();
    EmbreeScene::Hit hit;
    if (!embree_->Intersect(origin.cast<float>(), d.cast<float>(), 0.0F,
                            static_cast<float>(max_range_m), hit)) {
        return std::nullopt;
    }
    RayHit r;
    r.range_m = hit.t;
    r.point = origin + d * r.range_m;
    r.normal = hit.normal.cast<double>().normalized();
    if (r.normal.dot(d) > 0.0) r.normal = -r.normal;
    r.mesh = hit.geometry;
    r.label = labels_[hit.geometry];
    r.instance = instances_[hit.geometry];
    return r;
}

std::optional<double> Simulator::GroundHeight(double x, double y, double z_from) const {
    Eigen::Vector3d origin(x, y, z_from);
    // Look down through non-ground surfaces (foliage, vehicle roofs) until ground or nothing.
    for (int i = 0; i < 256; ++i) {
        const std::optional<RayHit> hit = CastRay(origin, -Eigen::Vector3d::UnitZ(), 1e4);
        if (!hit) return std::nullopt;
        if (kitti::IsGround(hit->label)) return hit->point.z();
        origin.z() = hit->point.z() - 1e-3;
    }
    return std::nullopt;
}

}  // namespace strata::sim
