#include <cmath>

#include "SceneParse.hpp"
#include "strata/sim/KittiIds.hpp"

// "building": storeys about 3.5 m apart, each with a corridor, rooms on both sides, an
// elevator shaft and a stairwell in a core at the west end (docs/simulator.md).
namespace strata::sim::detail {
namespace {

struct BuildingConfig {
    Eigen::Vector2d origin = Eigen::Vector2d::Zero();
    double z = 0.0;
    int floors = 3;
    double floor_height = 3.5, slab_thickness = 0.3;
    Eigen::Vector2d size = Eigen::Vector2d(30.0, 16.0);
    double corridor_width = 2.4, room_width = 4.0, core_length = 7.0;
    double exterior_slant_deg = 90.0;
    bool windows = true;
};

class FloorBuilder {
public:
    FloorBuilder(const BuildingConfig& c, SceneAssembler& a) : c_(c), a_(a) {}

    // A straight or polyline wall of storey k in building coordinates.
    void Wall(const std::string& name, std::vector<Eigen::Vector2d> path, int k, double thickness,
              std::vector<Opening> openings, double slant_deg = 90.0) {
        ObjectSpec o;
        o.name = name + "_f" + std::to_string(k);
        o.label = kitti::kBuilding;
        WallSpec w;
        w.kind = path.size() > 2 ? WallKind::kPolyline : WallKind::kFlat;
        for (Eigen::Vector2d& p : path) p += c_.origin;
        w.path = std::move(path);
        for (size_t i = 0; i + 1 < w.path.size(); ++i) {
            w.flat_parts.emplace_back(i, i + 1);
            w.part_ids.push_back(i == 0 ? 0 : a_.NewId());
        }
        w.z_base = Z(k);
        // Up to 1 cm under the slab above: coincident faces would make inside tests ambiguous.
        w.height_m = c_.floor_height - c_.slab_thickness - 0.01;
        w.thickness_m = thickness;
        w.slant_deg = slant_deg;
        w.openings = std::move(openings);
        w.floor = k;
        o.shape = std::move(w);
        a_.Add(std::move(o), "wall");
    }
    void Slab(const std::string& name, int k, std::vector<Eigen::AlignedBox2d> holes,
              uint16_t top) {
        ObjectSpec o;
        o.name = name;
        o.label = top;
        SlabSpec s;
        s.min_xy = c_.origin;
        s.max_xy = c_.origin + c_.size;
        s.z = Z(k);
        s.thickness_m = c_.slab_thickness;
        s.side_label = kitti::kBuilding;
        s.bottom_label = kitti::kBuilding;  // the ceiling of the storey below
        for (Eigen::AlignedBox2d& h : holes)
            s.holes.emplace_back(h.min() + c_.origin, h.max() + c_.origin);
        o.shape = std::move(s);
        a_.Add(std::move(o), "slab");
    }
    [[nodiscard]] double Z(int k) const { return c_.z + k * c_.floor_height; }

private:
    const BuildingConfig& c_;
    SceneAssembler& a_;
};

Opening Door(double u_centre) { return {u_centre - 0.45, u_centre + 0.45, -1.0, 2.1, -1.0}; }

}  // namespace

void GenerateBuilding(JsonReader& r, SceneAssembler& a) {
    BuildingConfig c;
    if (r.Has("origin")) c.origin = r.Vec2("origin");
    c.z = r.Get("z", c.z);
    c.floors = r.Get("floors", c.floors);
    c.floor_height = r.Get("floor_height", c.floor_height);
    c.slab_thickness = r.Get("slab_thickness", c.slab_thickness);
    if (r.Has("size")) c.size = r.Vec2("size");
    c.corridor_width = r.Get("corridor_width", c.corridor_width);
    c.room_width = r.Get("room_width", c.room_width);
    c.exterior_slant_deg = r.Get("exterior_slant_deg", c.exterior_slant_deg);
    c.windows = r.Get("windows", c.windows);
    if (c.floors < 1 || c.floor_height < 2.5 || c.size.x() < c.core_length + c.room_width ||
        c.size.y() < c.corridor_width + 6.0 || c.room_width < 2.0) {
        r.Fail("needs floors >= 1, floor_height >= 2.5 m, size >= [11, 8.4], room_width >= 2");
    }
    FloorBuilder b(c, a);
    const double Lx = c.size.x(), Ly = c.size.y(), core = c.core_length;
    const double yc0 = 0.5 * (Ly - c.corridor_width), yc1 = 0.5 * (Ly + c.corridor_width);
    const int rooms = static_cast<int>(std::floor((Lx - core) / c.room_width));
    // Stairwell: a straight flight along +x south of the lobby; elevator shaft north of it.
    const int steps = static_cast<int>(std::lround(c.floor_height / 0.175));
    const double run = std::min(0.28, (core - 1.2) / steps);
    const Eigen::AlignedBox2d stair_hole(Eigen::Vector2d(0.5, yc0 - 1.5),
                                         Eigen::Vector2d(0.6 + steps * run, yc0 - 0.2));
    const Eigen::AlignedBox2d shaft_hole(Eigen::Vector2d(2.2, yc1 + 0.2),
                                         Eigen::Vector2d(4.2, yc1 + 2.2));
    for (int k = 0; k <= c.floors; ++k) {
        std::vector<Eigen::AlignedBox2d> holes;
        if (k > 0 && k < c.floors) holes = {stair_hole, shaft_hole};
        b.Slab(k < c.floors ? "floor_" + std::to_string(k) : "roof", k, holes,
               k < c.floors ? kitti::kOtherGround : kitti::kBuilding);
        if (k == c.floors) break;
        a.spec().floor_z.push_back(b.Z(k));
        // Exterior walls, front face inside (counter-clockwise), one window per room.
        std::vector<Opening> windows;
        const double perimeter = 2.0 * (Lx + Ly);
        const double corners[3] = {Lx, Lx + Ly, 2 * Lx + Ly};
        for (double u = 1.5; c.windows && u + 1.2 < perimeter - 0.5; u += c.room_width) {
            bool straddles = false;
            for (double uc : corners) straddles = straddles || (uc > u - 0.3 && uc < u + 1.5);
            if (!straddles) windows.push_back({u, u + 1.2, 0.9, 2.3, -1.0});
        }
        b.Wall("exterior", {{0, 0}, {Lx, 0}, {Lx, Ly}, {0, Ly}, {0, 1e-3}}, k, 0.25, windows,
               c.exterior_slant_deg);
        // Corridor walls (front towards the corridor) with a door into every room.
        std::vector<Opening> south_doors, north_doors;
        for (int i = 0; i < rooms; ++i) {
            const double x = core + (i + 0.5) * c.room_width;
            south_doors.push_back(Door(x - core));
            north_doors.push_back(Door(Lx - x));
        }
        b.Wall("corridor_south", {{core, yc0}, {Lx, yc0}}, k, 0.15, south_doors);
        b.Wall("corridor_north", {{Lx, yc1}, {core, yc1}}, k, 0.15, north_doors);
        for (int i = 1; i < rooms; ++i) {
            const double x = core + i * c.room_width;
            b.Wall("partition_s" + std::to_string(i), {{x, 0.25}, {x, yc0}}, k, 0.12, {});
            b.Wall("partition_n" + std::to_string(i), {{x, yc1}, {x, Ly - 0.25}}, k, 0.12, {});
        }
        // Core: stairwell wall with a door, elevator shaft (clockwise: front outside) with a
        // door to the lobby on every storey, and the flight up to the next storey.
        b.Wall("stairwell", {{0.25, yc0 - 1.55}, {core, yc0 - 1.55}}, k, 0.15, {Door(5.5)});
        b.Wall("elevator_shaft",
               {{4.4, yc1}, {2.0, yc1}, {2.0, yc1 + 2.4}, {4.4, yc1 + 2.4}, {4.4, yc1 + 1e-3}}, k,
               0.2, {Door(1.2)});
        if (k + 1 < c.floors) {
            ObjectSpec stairs;
            stairs.name = "stairs_f" + std::to_string(k);
            stairs.label = kitti::kOtherStructure;
            StairsSpec s;
            s.start = Eigen::Vector3d(c.origin.x() + 0.6, c.origin.y() + yc0 - 0.85, b.Z(k));
            s.width_m = 1.2;
            s.steps = steps;
            s.rise_m = c.floor_height / steps;
            s.run_m = run;
            stairs.shape = s;
            a.Add(std::move(stairs), "stairs");
        }
    }
}

}  // namespace strata::sim::detail
