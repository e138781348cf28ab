#include <cmath>

#include "ObjectGeometry.hpp"
#include "SceneParse.hpp"
#include "strata/sim/KittiIds.hpp"

namespace strata::sim::detail {
namespace {

// A radius given as one number (a sphere) or as [rx, ry, rz].
Eigen::Vector3d Radii(JsonReader& r, const std::string& key, const Eigen::Vector3d& fallback) {
    if (!r.Has(key)) return fallback;
    const nlohmann::json& v = r.Raw(key);
    if (v.is_number()) return Eigen::Vector3d::Constant(v.get<double>());
    const auto a = r.Require<std::vector<double>>(key);
    if (a.size() != 3) r.Fail("'" + key + "' must be a number or [rx, ry, rz]");
    return {a[0], a[1], a[2]};
}

double Positive(JsonReader& r, const std::string& key, double fallback) {
    const double v = r.Get<double>(key, fallback);
    if (!(v > 0.0)) r.Fail("'" + key + "' must be positive");
    return v;
}

void ReadCommon(JsonReader& r, ObjectSpec& o, const char* default_class, float reflectivity) {
    o.name = r.Get<std::string>("name", "");
    o.label = ReadClass(r, "class", default_class);
    o.reflectivity = r.Get<float>("reflectivity", reflectivity);
    if (o.reflectivity < 0.0F || o.reflectivity > 1.0F) r.Fail("'reflectivity' must be in [0, 1]");
}

SlabSpec ParseSlab(JsonReader& r) {
    SlabSpec s;
    s.min_xy = r.Vec2("min");
    s.max_xy = r.Vec2("max");
    if ((s.max_xy - s.min_xy).minCoeff() <= 0.0) r.Fail("'max' must exceed 'min'");
    s.z = r.Get<double>("z", 0.0);
    if (r.Has("slope")) s.slope = r.Vec2("slope");
    s.thickness_m = r.Get<double>("thickness", 0.0);
    for (JsonReader& h : r.Items("holes")) {
        s.holes.emplace_back(h.Vec2("min"), h.Vec2("max"));
        h.Finish();
    }
    if (r.Has("side_class")) s.side_label = ReadClass(r, "side_class", "");
    if (r.Has("bottom_class")) s.bottom_label = ReadClass(r, "bottom_class", "");
    return s;
}

}  // namespace

uint16_t ReadClass(JsonReader& r, const std::string& key, const char* fallback) {
    const std::string name = r.Get<std::string>(key, fallback);
    try {
        return kitti::IdFromName(name);
    } catch (const InvalidArgumentError& e) {
        r.Fail("'" + key + "': " + e.what());
    }
}

ObjectSpec ParseObject(JsonReader& r, const std::string& kind, SceneAssembler& a) {
    ObjectSpec o;
    const double nan = std::nan("");
    if (kind == "ground") {
        ReadCommon(r, o, "road", 0.2F);
        o.shape = ParseSlab(r);
    } else if (kind == "vehicles") {
        VehicleSpec v;
        v.type = r.Get<std::string>("type", "car");
        VehicleType type;
        try {
            type = VehicleTypeOf(v.type);
        } catch (const InvalidArgumentError& e) {
            r.Fail(e.what());
        }
        ReadCommon(r, o, kitti::Name(type.label), 0.5F);
        v.center = r.Vec3("at", nan);
        if (std::isnan(v.center.z())) v.center.z() = a.GroundZ(v.center.x(), v.center.y());
        v.yaw_deg = r.Get<double>("yaw_deg", 0.0);
        v.size = type.size;
        if (r.Has("size")) v.size = Radii(r, "size", v.size);
        o.shape = v;
    } else if (kind == "trees" || kind == "bushes") {
        const bool tree = kind == "trees";
        ReadCommon(r, o, "vegetation", 0.45F);
        PlantSpec p;
        p.tree = tree;
        p.base = r.Vec3("at", nan);
        if (std::isnan(p.base.z())) p.base.z() = a.GroundZ(p.base.x(), p.base.y());
        const Eigen::Vector3d fallback =
            tree ? Eigen::Vector3d(2.2, 2.2, 2.0) : Eigen::Vector3d(1.0, 1.0, 0.7);
        p.crown_radii = Radii(r, tree ? "crown_radius" : "radius", fallback);
        const double height = Positive(r, "height", tree ? 7.0 : 2.0 * p.crown_radii.z());
        p.crown_center_height_m = height - p.crown_radii.z();
        p.trunk_radius_m = Positive(r, "trunk_radius", 0.15);
        p.leaf_size_m = Positive(r, "leaf_size", tree ? 0.15 : 0.1);
        p.leaves_per_m3 = Positive(r, "leaves_per_m3", tree ? 60.0 : 250.0);
        o.shape = p;
    } else if (kind == "poles") {
        ReadCommon(r, o, "pole", 0.5F);
        PoleSpec p;
        p.base = r.Vec3("at", nan);
        if (std::isnan(p.base.z())) p.base.z() = a.GroundZ(p.base.x(), p.base.y());
        p.height_m = Positive(r, "height", 6.0);
        p.radius_m = Positive(r, "radius", 0.08);
        p.sign = r.Get<bool>("sign", false);
        o.shape = p;
    } else if (kind == "boxes") {
        ReadCommon(r, o, "other-object", 0.4F);
        BoxSpec b;
        b.size = Radii(r, "size", Eigen::Vector3d(6.06, 2.44, 2.59));  // a 20 ft container
        b.center = r.Vec3("center", nan);
        b.yaw_deg = r.Get<double>("yaw_deg", 0.0);
        if (std::isnan(b.center.z())) {  // standing on the ground
            b.center.z() = a.GroundZ(b.center.x(), b.center.y()) + 0.5 * b.size.z();
            b.bottom = false;
        }
        o.shape = b;
    } else if (kind == "stairs") {
        ReadCommon(r, o, "other-structure", 0.3F);
        StairsSpec s;
        s.start = r.Vec3("start", nan);
        if (std::isnan(s.start.z())) s.start.z() = a.GroundZ(s.start.x(), s.start.y());
        s.yaw_deg = r.Get<double>("yaw_deg", 0.0);
        s.width_m = Positive(r, "width", 1.2);
        s.steps = r.Get<int>("steps", 18);
        s.rise_m = Positive(r, "rise", 0.175);
        s.run_m = Positive(r, "run", 0.28);
        if (s.steps < 1) r.Fail("'steps' must be at least 1");
        o.shape = s;
    } else {
        r.Fail("unknown object kind '" + kind + "'");
    }
    return o;
}

}  // namespace strata::sim::detail
