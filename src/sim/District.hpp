#pragma once

// "district": a grid of streets expanded into the scene file's own elements (private;
// docs/simulator.md, "Districts"). Every object is written as the JSON item a scene file would
// hold and read by the same parsers (ParseWall, ParseObject, ParseParkedCars, ParseSession),
// so a district is exactly the scene one would write by hand, only longer.
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "SceneParse.hpp"
#include "strata/sim/GroundTruth.hpp"

namespace strata::sim::detail {

struct DistrictRange {
    double lo = 0.0, hi = 0.0;
};

/// One facade kind of the five of the wall-slant study (adjoining walls stand at block corners).
struct FacadeKind {
    std::string kind;  ///< flat, curved_edge, half_curved, sliding_door, adjoining
    double weight = 1.0;
    DistrictRange length{12.0, 30.0};  ///< the straight part (adjoining: each arm)
    std::vector<double> slant_deg{90.0};
};

/// A recording: the streets around a rectangle of blocks, after some generated edits.
struct DistrictSession {
    std::string name;
    Eigen::Vector2i block_min{0, 0}, block_max{0, 0};  ///< inclusive block indices
    int remove = 0, move = 0, add = 0, containers = 0, demolish = 0, grow = 0;
};

/// The "district" block of a scene file, defaults filled in and validated.
struct DistrictConfig {
    Eigen::Vector2d origin = Eigen::Vector2d::Zero();  ///< south-west corner of everything
    Eigen::Vector2i blocks{2, 2};
    Eigen::Vector2d block_size{100.0, 100.0};  ///< kerb to kerb, sidewalks included
    double street_width = 20.0;                ///< kerb to kerb
    double sidewalk = 4.0;                     ///< kerb to facade line
    DistrictRange height{7.0, 16.0};
    double thickness = 0.35;
    DistrictRange gap{2.0, 8.0};  ///< between neighbouring buildings
    double windows = 0.8;         ///< share of facades with a window grid
    double corners = 0.5;         ///< share of block corners with an adjoining wall
    std::vector<FacadeKind> kinds;
    nlohmann::json car_keys = nlohmann::json::object();  ///< passed on to each parked_cars line
    std::vector<std::string> car_types{"car", "car", "suv", "van"};  ///< also for arrivals
    double car_spacing = 6.5, car_end_margin = 6.0;
    double tree_spacing = 20.0, tree_fill = 0.6;
    DistrictRange tree_height{5.5, 8.0}, crown_radius{1.4, 1.8};
    double bushes = 0.3;  ///< share of flat facades with a bush in front
    double pole_spacing = 40.0;
    double speed = 10.0, sensor_height = 1.73, lane_offset = 2.5;
    double corner = 0.0, sway_deg = 0.0;  ///< TrajectorySpec's corner_m and sway_deg
    int every = 10;
    double edits_across = 0.0;  ///< > 0: edits prefer objects across lines x, y = k * this
    std::vector<DistrictSession> sessions;

    [[nodiscard]] Eigen::Vector2d Pitch() const {
        return block_size + Eigen::Vector2d::Constant(street_width);
    }
    /// Lower corner of block (i, j), at its kerbs.
    [[nodiscard]] Eigen::Vector2d BlockMin(int i, int j) const;
    /// Centre line of street k running along `axis`: its y for 0 (along x), its x for 1.
    [[nodiscard]] double StreetCentre(int axis, int k) const;
    /// Size of everything, outer sidewalks included.
    [[nodiscard]] Eigen::Vector2d Extent() const;
};

/// A street between two crossings: `axis` 0 runs along x (at y = const), 1 along y.
struct Segment {
    int axis = 0, street = 0, index = 0;
    [[nodiscard]] bool operator==(const Segment& o) const {
        return axis == o.axis && street == o.street && index == o.index;
    }
};

/// What the edits may change, recorded while the district is generated.
struct DistrictPlan {
    struct Slot {  ///< a parking place at a kerb
        Segment segment;
        Eigen::Vector2d at = Eigen::Vector2d::Zero();
        double yaw_deg = 0.0;
        Eigen::AlignedBox2d box;  ///< footprint of what stands there (or of a car)
        std::string occupant;     ///< the vehicle or box there, "" when free
        bool container = false;   ///< the occupant is a container (not a vehicle)
        int freed_in = -1;        ///< session that freed it (not refilled in that session)
    };
    struct Item {  ///< a wall that can be cut or a plant that can grow
        Segment segment;
        std::string name;
        Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();  ///< base / box
        bool used = false;
    };
    std::vector<Slot> slots;
    std::vector<Item> walls;   ///< flat walls: a, b = base path start and end
    std::vector<Item> bushes;  ///< a, b = crown box corners (x, y)
    std::vector<Item> trees;   ///< as bushes (grown only where no bush can be)
};

/// [x, y] as JSON.
[[nodiscard]] inline nlohmann::json JsonXy(const Eigen::Vector2d& p) {
    return nlohmann::json::array({p.x(), p.y()});
}

/// A plant that can grow: its crown box seen from above.
[[nodiscard]] inline DistrictPlan::Item PlantItem(const Segment& segment, const BoxTruth& crown) {
    const Eigen::Vector2d half = 0.5 * crown.size.head<2>();
    return {segment, crown.name, crown.center.head<2>() - half, crown.center.head<2>() + half,
            false};
}

/// Reads and checks the block (sizes bounded so that no input generates without end).
[[nodiscard]] DistrictConfig ReadDistrict(JsonReader& r);
/// Reads a generated item as the scene file's list `list` would ("walls", "trees", ...).
ObjectSpec& AddDistrictItem(SceneAssembler& a, const std::string& list, const nlohmann::json& item);

/// A street segment: t along it from its first crossing, offsets to the left of +t.
struct SegmentFrame {
    Eigen::Vector2d p0, d, left;
    double length = 0.0;
    std::string name;  ///< ew<street>_<index> or ns<street>_<index>
    [[nodiscard]] Eigen::Vector2d At(double t, double offset) const {
        return p0 + t * d + offset * left;
    }
};
[[nodiscard]] SegmentFrame FrameOf(const DistrictConfig& c, const Segment& s);

void AddDistrictStreets(const DistrictConfig& c, SceneAssembler& a, DistrictPlan& plan);
/// Parked cars at the kerb on `side` (-1: right of +t, 1: left), their slots into the plan.
void AddDistrictKerb(const DistrictConfig& c, const Segment& seg, const SegmentFrame& f,
                     double side, SceneAssembler& a, DistrictPlan& plan);
/// Trees and street lights on the sidewalk on `side`, the trees into the plan.
void AddDistrictSidewalk(const DistrictConfig& c, const Segment& seg, const SegmentFrame& f,
                         double side, SceneAssembler& a, DistrictPlan& plan);
void AddDistrictFacades(const DistrictConfig& c, SceneAssembler& a, DistrictPlan& plan);
/// The route of a session: every street around its blocks, as waypoints [x, y].
[[nodiscard]] std::vector<Eigen::Vector2d> DistrictRoute(const DistrictConfig& c,
                                                         const DistrictSession& s);
/// True when the session drives along the segment.
[[nodiscard]] bool Drives(const DistrictSession& s, const Segment& segment);
/// The edits of session k (relative to session k - 1), as scene-file edit items.
[[nodiscard]] nlohmann::json DistrictEdits(const DistrictConfig& c, size_t k, SceneAssembler& a,
                                           DistrictPlan& plan);

}  // namespace strata::sim::detail
