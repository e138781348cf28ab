#include "strata/sim/SimulateScene.hpp"

namespace strata::sim {
namespace {

// A 60 m street: kerbs, two facades (one leaning 2 degrees), parked cars, trees and a pole.
// Kept small so that `strata demo` runs in seconds; datasets/scenes/street.json is the full one.
constexpr const char* kDemoStreet = R"json({
  "name": "demo_street",
  "seed": 7,
  "sensor": "hdl64",
  "ground": [
    {"name": "road", "class": "road", "min": [-5, -5], "max": [65, 5], "slope": [0.01, 0]},
    {"name": "sidewalk_south", "class": "sidewalk", "min": [-5, -8], "max": [65, -5],
     "z": 0.15, "slope": [0.01, 0], "thickness": 0.15},
    {"name": "sidewalk_north", "class": "sidewalk", "min": [-5, 5], "max": [65, 8],
     "z": 0.15, "slope": [0.01, 0], "thickness": 0.15}
  ],
  "walls": [
    {"name": "facade_south", "kind": "flat", "start": [0, -8], "end": [28, -8], "height": 9,
     "thickness": 0.4, "slant_deg": 88, "windows": {"spacing": 3.5}},
    {"name": "facade_north", "kind": "flat", "start": [60, 8], "end": [20, 8], "height": 12,
     "thickness": 0.4, "windows": {"spacing": 3.0}}
  ],
  "vehicles": [
    {"name": "car_1", "type": "car", "at": [10, -3.9]},
    {"name": "car_2", "type": "suv", "at": [17, -3.9]},
    {"name": "car_3", "type": "van", "at": [36, 3.9], "yaw_deg": 180},
    {"name": "car_4", "type": "car", "at": [48, 3.9], "yaw_deg": 180}
  ],
  "trees": [{"at": [25, -6.6], "crown_radius": 1.6}, {"at": [42, 6.6], "crown_radius": 1.6}],
  "poles": [{"at": [33, -5.4], "height": 7, "sign": true}],
  "trajectory": {"waypoints": [[2, -1.5], [58, -1.5]], "speed": 8, "every": 6, "max_scans": 10}
})json";

}  // namespace

SceneSpec DemoStreetScene() { return ParseSceneSpec(kDemoStreet, "<demo street>"); }

}  // namespace strata::sim
