#include <cmath>

#include "MeshBuilders.hpp"
#include "ObjectGeometry.hpp"
#include "Rng.hpp"
#include "SceneParse.hpp"

namespace strata::sim::detail {

// "parked_cars": vehicles in slots along a kerb line, some slots left empty.
void ParseParkedCars(JsonReader& r, SceneAssembler& a) {
    const Eigen::Vector2d from = r.Vec2("from");
    const Eigen::Vector2d to = r.Vec2("to");
    const double spacing = r.Get<double>("spacing", 6.5);
    const double fill = r.Get<double>("fill", 0.75);
    const double jitter_deg = r.Get<double>("yaw_jitter_deg", 2.0);
    const auto types = r.Get<std::vector<std::string>>("types", {"car", "car", "suv", "van"});
    const std::string prefix = r.Get<std::string>("name", "parked");
    if (spacing < 3.0 || fill < 0.0 || fill > 1.0 || types.empty()) {
        r.Fail("needs spacing >= 3, fill in [0, 1] and at least one type");
    }
    const Eigen::Vector2d d = (to - from).normalized();
    const double yaw = RadToDeg(std::atan2(d.y(), d.x()));
    const double length = (to - from).norm();
    Rng rng(HashKey(a.seed(), 0xCA45, a.spec().objects.size()));
    int slot = 0;
    for (double s = 0.5 * spacing; s + 0.5 * spacing <= length + 1e-9; s += spacing, ++slot) {
        if (rng.Uniform() >= fill) continue;
        const std::string type = types[static_cast<size_t>(rng.Next() % types.size())];
        const VehicleType vt = VehicleTypeOf(type);
        VehicleSpec v;
        v.type = type;
        v.size = vt.size;
        const Eigen::Vector2d left(-d.y(), d.x());
        // One draw per statement: operands of + are evaluated in an unspecified order (gcc
        // drew the sideways offset first, clang the one along the kerb), and a scene must not
        // depend on the compiler. The order is the one gcc builds always had.
        const double sideways_m = rng.Uniform(-0.1, 0.1);
        const double along_m = rng.Uniform(-0.4, 0.4);
        const Eigen::Vector2d xy = from + (s + along_m) * d + sideways_m * left;
        v.center = Eigen::Vector3d(xy.x(), xy.y(), a.GroundZ(xy.x(), xy.y()));
        // Some drivers park nose first, some reverse in; all a little crooked.
        const bool reversed = rng.Uniform() >= 0.8;
        const double crooked_deg = rng.Uniform(-1, 1) * jitter_deg;
        v.yaw_deg = yaw + (reversed ? 180.0 : 0.0) + crooked_deg;
        ObjectSpec o;
        o.name = prefix + "_" + std::to_string(slot);
        o.label = vt.label;
        o.reflectivity = static_cast<float>(rng.Uniform(0.3, 0.7));
        o.shape = v;
        a.Add(std::move(o), "vehicle");
    }
}

}  // namespace strata::sim::detail
