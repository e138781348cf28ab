#include <algorithm>
#include <set>

#include "MeshBuilders.hpp"
#include "ObjectGeometry.hpp"
#include "Rng.hpp"
#include "SceneParse.hpp"
#include "strata/sim/KittiIds.hpp"

// "parking_garage": an underground level with pillars, a ceiling, painted bays, parked
// vehicles of several sizes, a few empty bays, a drain and a ramp edge (docs/simulator.md).
namespace strata::sim::detail {
namespace {

struct GarageConfig {
    Eigen::Vector2d origin = Eigen::Vector2d::Zero();
    double z = 0.0;
    int rows = 4;  // even: pairs of rows face one aisle each
    int bays_per_row = 12;
    double bay_width = 2.5, bay_depth = 5.0, aisle_width = 6.5, end_aisle = 6.5;
    double ceiling_height = 2.8, pillar_size = 0.4;
    int pillar_every = 3;
    double occupancy = 0.85;
    int empty_bays = 3;  // at least this many bays stay empty whatever the occupancy
    std::vector<std::string> types = {"car", "car", "suv", "van"};
    bool drain = true, ramp = true;
};

GarageConfig ReadConfig(JsonReader& r) {
    GarageConfig c;
    if (r.Has("origin")) c.origin = r.Vec2("origin");
    c.z = r.Get("z", c.z);
    c.rows = r.Get("rows", c.rows);
    c.bays_per_row = r.Get("bays_per_row", c.bays_per_row);
    c.bay_width = r.Get("bay_width", c.bay_width);
    c.bay_depth = r.Get("bay_depth", c.bay_depth);
    c.aisle_width = r.Get("aisle_width", c.aisle_width);
    c.end_aisle = r.Get("end_aisle", c.end_aisle);
    c.ceiling_height = r.Get("ceiling_height", c.ceiling_height);
    c.pillar_size = r.Get("pillar_size", c.pillar_size);
    c.pillar_every = r.Get("pillar_every", c.pillar_every);
    c.occupancy = r.Get("occupancy", c.occupancy);
    c.empty_bays = r.Get("empty_bays", c.empty_bays);
    c.types = r.Get("types", c.types);
    c.drain = r.Get("drain", c.drain);
    c.ramp = r.Get("ramp", c.ramp);
    if (c.rows < 2 || c.rows % 2 != 0 || c.bays_per_row < 1 || c.pillar_every < 1) {
        r.Fail("rows must be even and >= 2; bays_per_row and pillar_every >= 1");
    }
    if (c.occupancy < 0 || c.occupancy > 1 || c.types.empty() || c.end_aisle < 5.0) {
        r.Fail("occupancy in [0, 1], at least one vehicle type, end_aisle >= 5 m");
    }
    return c;
}

void AddSlab(SceneAssembler& a, const std::string& name, uint16_t label, const SlabSpec& slab,
             float reflectivity) {
    ObjectSpec o;
    o.name = name;
    o.label = label;
    o.reflectivity = reflectivity;
    o.shape = slab;
    a.Add(std::move(o), "slab");
}

SlabSpec Rect(double x0, double y0, double x1, double y1, double z) {
    SlabSpec s;
    s.min_xy = {x0, y0};
    s.max_xy = {x1, y1};
    s.z = z;
    return s;
}

}  // namespace

void GenerateParkingGarage(JsonReader& r, SceneAssembler& a) {
    const GarageConfig c = ReadConfig(r);
    const double ox = c.origin.x(), oy = c.origin.y(), z = c.z;
    const double W = c.bays_per_row * c.bay_width;
    const double pair = 2 * c.bay_depth + c.aisle_width;
    const double Ly = (c.rows / 2) * pair;
    const double x0 = ox - c.end_aisle, x1 = ox + W + c.end_aisle;
    const double y0 = oy - 0.3, y1 = oy + Ly + 0.3;
    SceneSpec& spec = a.spec();
    // Step 1: the floor, with a drain across the first aisle and a ramp hole in the east aisle.
    SlabSpec floor = Rect(x0, y0, x1, y1, z);
    floor.thickness_m = 0.3;
    floor.side_label = kitti::kOtherGround;
    if (c.drain) {
        const Eigen::AlignedBox2d drain(
            Eigen::Vector2d(ox + 0.5 * W, oy + c.bay_depth),
            Eigen::Vector2d(ox + 0.5 * W + 0.3, oy + c.bay_depth + c.aisle_width));
        floor.holes.push_back(drain);
        spec.gaps.push_back({"drain", "drain", drain, z});
        SlabSpec bottom =
            Rect(drain.min().x(), drain.min().y(), drain.max().x(), drain.max().y(), z - 0.3);
        AddSlab(a, "drain_bottom", kitti::kOtherGround, bottom, 0.1F);
    }
    if (c.ramp) {
        const Eigen::AlignedBox2d hole(Eigen::Vector2d(ox + W + 0.8, y1 - 10.0),
                                       Eigen::Vector2d(x1 - 0.8, y1));
        floor.holes.push_back(hole);
        // The ramp falls 3 m towards the north wall; a 0.5 m gap on each side is a real drop.
        SlabSpec ramp =
            Rect(hole.min().x() + 0.5, hole.min().y(), hole.max().x() - 0.5, hole.max().y(), 0.0);
        ramp.slope = Eigen::Vector2d(0.0, -3.0 / hole.sizes().y());
        ramp.z = z - ramp.slope.y() * hole.min().y();
        ramp.thickness_m = 0.2;
        AddSlab(a, "ramp", kitti::kRoad, ramp, 0.2F);
        AddSlab(a, "lower_level", kitti::kOtherGround,
                Rect(hole.min().x(), hole.min().y(), hole.max().x(), hole.max().y(), z - 3.0),
                0.2F);
        for (double gx : {hole.min().x(), hole.max().x() - 0.5}) {
            const Eigen::AlignedBox2d gap(Eigen::Vector2d(gx, hole.min().y()),
                                          Eigen::Vector2d(gx + 0.5, hole.max().y()));
            spec.gaps.push_back(
                {"ramp_edge_" + std::to_string(spec.gaps.size()), "ramp_edge", gap, z});
        }
    }
    AddSlab(a, "garage_floor", kitti::kParking, floor, 0.2F);
    // Step 2: ceiling slab and the perimeter wall (front face inside).
    SlabSpec ceiling = Rect(x0, y0, x1, y1, z + c.ceiling_height + 0.3);
    ceiling.thickness_m = 0.3;
    ceiling.bottom_label = kitti::kBuilding;
    AddSlab(a, "ceiling", kitti::kBuilding, ceiling, 0.3F);
    ObjectSpec walls;
    walls.name = "garage_walls";
    walls.label = kitti::kBuilding;
    WallSpec w;
    w.kind = WallKind::kPolyline;
    w.path = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0 + 1e-3}};
    for (int i = 0; i < 4; ++i) w.flat_parts.emplace_back(i, i + 1);
    w.part_ids = {0, a.NewId(), a.NewId(), a.NewId()};
    w.z_base = z;
    w.height_m = c.ceiling_height;
    w.thickness_m = 0.3;
    walls.shape = w;
    a.Add(std::move(walls), "wall");
    // Step 3: rows of bays: painted lines, pillars on the back lines, parked vehicles.
    Rng rng(HashKey(a.seed(), 0x6A4A6E, static_cast<uint64_t>(c.rows * c.bays_per_row)));
    std::set<int> forced_empty;
    while (static_cast<int>(forced_empty.size()) <
           std::min(c.empty_bays, c.rows * c.bays_per_row)) {
        forced_empty.insert(static_cast<int>(rng.Next() % uint64_t(c.rows * c.bays_per_row)));
    }
    for (int row = 0; row < c.rows; ++row) {
        const bool faces_north = row % 2 == 0;
        const double ylo =
            oy + (row / 2) * pair + (faces_north ? 0.0 : c.bay_depth + c.aisle_width);
        const double back = faces_north ? ylo : ylo + c.bay_depth;
        for (int k = 0; k <= c.bays_per_row; ++k) {
            const double x = ox + k * c.bay_width;
            SlabSpec line = Rect(x - 0.06, ylo + 0.1, x + 0.06, ylo + c.bay_depth - 0.1, z + 0.003);
            AddSlab(a, "", kitti::kLaneMarking, line, 0.85F);
            if (k % c.pillar_every == 0 && (faces_north ? row > 0 : row + 1 < c.rows)) {
                ObjectSpec pillar;
                pillar.label = kitti::kOtherStructure;
                const double py = back + (faces_north ? 0.5 : -0.5) * c.pillar_size;
                // 1 cm short of the ceiling, so that no two faces coincide.
                const double height = c.ceiling_height - 0.01;
                pillar.shape = BoxSpec{
                    {x, py, z + 0.5 * height}, {c.pillar_size, c.pillar_size, height}, 0.0, false};
                a.Add(std::move(pillar), "pillar");
            }
        }
        for (int b = 0; b < c.bays_per_row; ++b) {
            const bool occupied = rng.Uniform() < c.occupancy;
            const std::string type = c.types[static_cast<size_t>(rng.Next() % c.types.size())];
            const double gap = rng.Uniform(0.2, 0.5), lateral = rng.Uniform(-0.1, 0.1);
            const bool reversed = rng.Uniform() < 0.3;
            const double yaw_jitter = rng.Uniform(-2.5, 2.5);
            if (!occupied || forced_empty.count(row * c.bays_per_row + b) > 0) continue;
            const VehicleType vt = VehicleTypeOf(type);
            VehicleSpec v;
            v.type = type;
            v.size = vt.size;
            const double cy =
                faces_north ? back + gap + 0.5 * v.size.x() : back - gap - 0.5 * v.size.x();
            v.center = {ox + (b + 0.5) * c.bay_width + lateral, cy, z};
            v.yaw_deg = (faces_north ? 90.0 : -90.0) + (reversed ? 180.0 : 0.0) + yaw_jitter;
            ObjectSpec o;
            o.name = "bay_" + std::to_string(row) + "_" + std::to_string(b);
            o.label = vt.label;
            o.reflectivity = static_cast<float>(0.3 + 0.4 * rng.Uniform());
            o.shape = v;
            a.Add(std::move(o), "vehicle");
        }
    }
}

}  // namespace strata::sim::detail
