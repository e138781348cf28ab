#include "strata/sim/KittiIds.hpp"

#include <array>
#include <cctype>
#include <stdexcept>

#include "strata/core/Error.hpp"

namespace strata::sim::kitti {
namespace {

struct ClassEntry {
    uint16_t id;
    const char* name;
    core::Rgb color;
};

// Names as in the SemanticKITTI label definition; colours are our own, chosen so that classes
// that share a strata class (road, sidewalk, parking, markings) stay apart in a picture.
constexpr std::array<ClassEntry, 25> kEntries = {{
    {kUnlabeled, "unlabeled", {0, 0, 0}},
    {kCar, "car", {40, 90, 230}},
    {kBus, "bus", {20, 50, 170}},
    {kTruck, "truck", {70, 40, 180}},
    {kOtherVehicle, "other-vehicle", {90, 140, 255}},
    {kPerson, "person", {255, 40, 200}},
    {kBicyclist, "bicyclist", {200, 40, 255}},
    {kRoad, "road", {90, 90, 95}},
    {kParking, "parking", {130, 110, 140}},
    {kSidewalk, "sidewalk", {175, 170, 165}},
    {kOtherGround, "other-ground", {150, 120, 90}},
    {kBuilding, "building", {235, 140, 50}},
    {kFence, "fence", {170, 110, 220}},
    {kOtherStructure, "other-structure", {200, 90, 60}},
    {kLaneMarking, "lane-marking", {250, 250, 250}},
    {kVegetation, "vegetation", {40, 170, 40}},
    {kTrunk, "trunk", {110, 70, 30}},
    {kTerrain, "terrain", {150, 200, 90}},
    {kPole, "pole", {250, 230, 100}},
    {kTrafficSign, "traffic-sign", {230, 30, 30}},
    {kOtherObject, "other-object", {0, 200, 200}},
    {kMovingCar, "moving-car", {255, 215, 0}},
    {kMovingBicyclist, "moving-bicyclist", {255, 120, 0}},
    {kMovingPerson, "moving-person", {255, 60, 60}},
    {kMovingTruck, "moving-truck", {230, 170, 0}},
}};

}  // namespace

uint16_t IdFromName(const std::string& name) {
    for (const ClassEntry& e : kEntries) {
        if (name == e.name) return e.id;
    }
    const bool numeric = !name.empty() && name.size() <= 5 &&
                         name.find_first_not_of("0123456789") == std::string::npos;
    if (numeric) {
        const unsigned long id = std::stoul(name);
        for (const ClassEntry& e : kEntries) {
            if (id == e.id) return e.id;
        }
    }
    throw InvalidArgumentError("unknown SemanticKITTI class '" + name + "'");
}

const char* Name(uint16_t id) {
    for (const ClassEntry& e : kEntries) {
        if (id == e.id) return e.name;
    }
    return "unknown";
}

core::Rgb Color(uint16_t id) {
    for (const ClassEntry& e : kEntries) {
        if (id == e.id) return e.color;
    }
    return {128, 128, 128};
}

bool IsGround(uint16_t id) {
    return id == kRoad || id == kParking || id == kSidewalk || id == kOtherGround ||
           id == kLaneMarking || id == kTerrain;
}

}  // namespace strata::sim::kitti
