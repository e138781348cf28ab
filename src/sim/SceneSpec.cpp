#include "strata/sim/SceneSpec.hpp"

#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "ObjectGeometry.hpp"
#include "SceneParse.hpp"
#include "strata/core/Error.hpp"
#include "strata/sim/KittiIds.hpp"

namespace strata::sim {
namespace detail {

ObjectSpec& SceneAssembler::Add(ObjectSpec object, const std::string& prefix) {
    object.id = NewId();
    if (auto* wall = std::get_if<WallSpec>(&object.shape); wall && !wall->part_ids.empty()) {
        wall->part_ids[0] = object.id;  // the first straight part carries the object's id
    }
    if (object.name.empty()) object.name = prefix + "_" + std::to_string(object.id);
    spec_.objects.push_back(std::move(object));
    return spec_.objects.back();
}

int SceneAssembler::NewId() {
    if (next_id_ > 65535) throw FormatError(spec_.source + ": more than 65535 objects");
    return next_id_++;
}

double SceneAssembler::GroundZ(double x, double y, double fallback) const {
    double best = -std::numeric_limits<double>::infinity();
    for (const ObjectSpec& o : spec_.objects) {
        const auto* slab = std::get_if<SlabSpec>(&o.shape);
        if (slab == nullptr || !kitti::IsGround(o.label) || !SlabCovers(*slab, x, y)) continue;
        best = std::max(best, SlabTopZ(*slab, x, y));
    }
    return std::isfinite(best) ? best : fallback;
}

}  // namespace detail

namespace {

[[noreturn]] void FailRead(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw NotFoundError("no scene file " + path.string());
    throw IoError("cannot read scene file " + path.string());
}

using nlohmann::json;

// "include": "base.json" merges a base file under this one (keys here replace the base's).
json ResolveIncludes(json j, const std::filesystem::path& dir, const std::string& source,
                     int depth) {
    if (!j.is_object() || !j.contains("include")) return j;
    if (depth > 4) throw FormatError(source + ": 'include' nested too deeply");
    const std::filesystem::path base_path = dir / j.at("include").get<std::string>();
    std::ifstream in(base_path);
    if (!in) FailRead(base_path);
    json base;
    try {
        base = json::parse(in);
    } catch (const json::parse_error& e) {
        throw FormatError("cannot parse scene file " + base_path.string() + ": " + e.what());
    }
    base = ResolveIncludes(std::move(base), base_path.parent_path(), base_path.string(), depth + 1);
    j.erase("include");
    base.update(j);
    return base;
}

SceneSpec ParseJson(const json& root, const std::string& source) {
    SceneSpec spec;
    spec.source = source;
    detail::JsonReader r(root, source, "");
    spec.name = r.Get<std::string>("name", "scene");
    spec.seed = r.Get<uint64_t>("seed", 1);
    spec.sensor = r.Get<std::string>("sensor", "hdl64");
    spec.surface_spacing_m = r.Get<double>("surface_spacing", spec.surface_spacing_m);
    if (!(spec.surface_spacing_m >= 0.01 && spec.surface_spacing_m <= 10.0)) {
        r.Fail("'surface_spacing' must be in [0.01, 10] m");
    }
    (void)r.Has("description");  // free text for people
    detail::SceneAssembler a(spec);
    // Generators first (they lay the ground the other objects stand on), then object lists.
    if (r.Has("parking_garage")) {
        detail::JsonReader g = r.Child("parking_garage");
        detail::GenerateParkingGarage(g, a);
    }
    if (r.Has("building")) {
        detail::JsonReader g = r.Child("building");
        detail::GenerateBuilding(g, a);
    }
    if (r.Has("district")) {
        if (r.Has("sessions") || r.Has("trajectory")) {
            r.Fail("a 'district' drives its own sessions: no 'sessions' or 'trajectory' beside it");
        }
        detail::JsonReader g = r.Child("district");
        detail::GenerateDistrict(g, a);
    }
    const std::pair<const char*, const char*> kinds[] = {
        {"ground", "ground"}, {"walls", "wall"}, {"vehicles", "vehicle"}, {"trees", "tree"},
        {"bushes", "bush"},   {"poles", "pole"}, {"boxes", "box"},        {"stairs", "stairs"}};
    for (const auto& [kind, prefix] : kinds) {
        for (detail::JsonReader& item : r.Items(kind)) {
            ObjectSpec object = kind == std::string("walls") ? detail::ParseWall(item, a)
                                                             : detail::ParseObject(item, kind, a);
            item.Finish();
            a.Add(std::move(object), prefix);
        }
    }
    for (detail::JsonReader& item : r.Items("parked_cars")) {
        detail::ParseParkedCars(item, a);
        item.Finish();
    }
    TrajectorySpec trajectory;
    if (r.Has("trajectory")) {
        detail::JsonReader t = r.Child("trajectory");
        trajectory = detail::ParseTrajectory(t);
    }
    for (detail::JsonReader& item : r.Items("sessions")) {
        spec.sessions.push_back(detail::ParseSession(item, trajectory, a));
        item.Finish();
    }
    if (spec.sessions.empty()) {
        SessionSpec session;
        session.name = "session_0";
        session.trajectory = trajectory;
        spec.sessions.push_back(session);
    }
    r.Finish();
    spec.Validate();
    return spec;
}

}  // namespace

void SceneSpec::Validate() const {
    std::set<int> ids;
    std::set<std::string> names;
    for (const ObjectSpec& o : objects) {
        if (!ids.insert(o.id).second) {
            throw FormatError(source + ": duplicate object id " + std::to_string(o.id));
        }
        if (!names.insert(o.name).second) {
            throw FormatError(source + ": duplicate object name '" + o.name + "'");
        }
    }
    if (sessions.empty()) throw FormatError(source + ": no sessions");
    for (size_t s = 0; s < sessions.size(); ++s) {
        if (sessions[s].trajectory.waypoints.empty()) {
            throw FormatError(source + ": session '" + sessions[s].name +
                              "' has no trajectory waypoints");
        }
        (void)ObjectsOfSession(*this, s);  // throws on an edit of an unknown object
        std::set<std::string> actor_names;
        for (const ActorSpec& a : sessions[s].traffic) {
            const std::string at = source + ": session '" + sessions[s].name + "': ";
            if (!ids.insert(a.id).second) {
                throw FormatError(at + "actor '" + a.name + "' has the id of another object (" +
                                  std::to_string(a.id) + ")");
            }
            if (!actor_names.insert(a.name).second) {
                throw FormatError(at + "duplicate actor name '" + a.name + "'");
            }
            try {
                a.Validate();
            } catch (const InvalidArgumentError& e) {
                throw FormatError(at + e.what());
            }
        }
    }
}

size_t SceneSpec::IndexOf(const std::string& object_name) const {
    for (size_t i = 0; i < objects.size(); ++i) {
        if (objects[i].name == object_name) return i;
    }
    throw FormatError(source + ": no object named '" + object_name + "'");
}

SceneSpec ParseSceneSpec(const std::string& json_text, const std::string& source) {
    json root;
    try {
        root = json::parse(json_text);
    } catch (const json::parse_error& e) {
        throw FormatError("cannot parse scene file " + source + ": " + e.what());
    }
    const std::filesystem::path dir = std::filesystem::path(source).parent_path();
    return ParseJson(ResolveIncludes(std::move(root), dir, source, 0), source);
}

SceneSpec LoadSceneSpec(const std::filesystem::path& path) {
    std::ifstream in(path);
    if (!in) FailRead(path);
    std::ostringstream text;
    text << in.rdbuf();
    return ParseSceneSpec(text.str(), path.string());
}

}  // namespace strata::sim
