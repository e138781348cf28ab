#include "ObjectGeometry.hpp"
#include "SessionEdits.hpp"
#include "WallGeometry.hpp"
#include "strata/sim/Scene.hpp"

namespace strata::sim {

void Mesh::Append(const Mesh& other) {
    const auto offset = static_cast<uint32_t>(vertices.size());
    vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
    for (const auto& t : other.triangles) {
        triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    }
}

double Mesh::Area() const {
    double area = 0.0;
    for (const auto& t : triangles) {
        const Eigen::Vector3d a = vertices[t[0]].cast<double>();
        area += 0.5 *
                (vertices[t[1]].cast<double>() - a).cross(vertices[t[2]].cast<double>() - a).norm();
    }
    return area;
}

size_t Scene::TriangleCount() const {
    size_t n = 0;
    for (const Mesh& m : meshes) n += m.triangles.size();
    return n;
}

Scene BuildScene(const SceneSpec& spec, size_t session) {
    detail::SessionObjects objects = detail::ApplySessionEdits(spec, session);
    const SessionSpec& ss = spec.sessions[session];
    Scene scene;
    GroundTruth& truth = scene.truth;
    truth.scene = spec.name;
    truth.session = ss.name;
    truth.session_index = static_cast<int>(session);
    truth.T_world_session = ss.T_world_session;
    truth.sensor = spec.sensor;
    truth.seed = spec.seed;
    truth.edits = std::move(objects.edits);
    for (const ObjectSpec& o : objects.objects) {
        for (Mesh& m : detail::BuildObjectMeshes(o, spec.seed))
            scene.meshes.push_back(std::move(m));
        if (const auto* wall = std::get_if<WallSpec>(&o.shape)) {
            for (WallTruth& w : detail::WallTruths(o, *wall)) truth.walls.push_back(std::move(w));
        } else if (std::holds_alternative<VehicleSpec>(o.shape)) {
            truth.vehicles.push_back(detail::ObjectBox(o));
        }
    }
    // Each storey's frame is the frame of the session that scanned it (identity + z otherwise).
    for (size_t k = 0; k < spec.floor_z.size(); ++k) {
        FloorTruth f;
        f.index = static_cast<int>(k);
        f.z_offset = spec.floor_z[k];
        f.T_world_floor = Eigen::Isometry3d(Eigen::Translation3d(0, 0, spec.floor_z[k]));
        for (const SessionSpec& s : spec.sessions) {
            if (s.floor == f.index) f.T_world_floor = s.T_world_session;
        }
        truth.floors.push_back(f);
    }
    // Traffic: traced by the simulator at each sweep's time, reported apart from the vehicles.
    scene.actors = ss.traffic;
    for (const ActorSpec& a : ss.traffic) {
        truth.actors.push_back(
            {a.id, a.name, a.type, a.start_s, a.EndS(), a.before, a.after, a.speed_mps, a.path});
    }
    for (const GapSpec& g : spec.gaps) {
        const Eigen::Vector2d a = g.box.min(), b = g.box.max();
        truth.gaps.push_back(
            {g.name,
             g.kind,
             {{a.x(), a.y(), g.z}, {b.x(), a.y(), g.z}, {b.x(), b.y(), g.z}, {a.x(), b.y(), g.z}}});
    }
    scene.bounds.setEmpty();
    for (const Mesh& m : scene.meshes) {
        for (const Eigen::Vector3f& v : m.vertices) scene.bounds.extend(v.cast<double>());
    }
    return scene;
}

}  // namespace strata::sim
