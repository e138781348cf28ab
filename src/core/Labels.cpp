#include "strata/core/Labels.hpp"

#include <nlohmann/json.hpp>
#include <stdexcept>

#include "strata/core/Error.hpp"

namespace strata::core {
namespace {

struct ClassInfo {
    const char* name;
    Rgb color;
};

// Indexed by SemanticClass. Colours are chosen to stay distinct in a top-down picture.
constexpr std::array<ClassInfo, kNumClasses> kClasses = {{
    {"unknown", {128, 128, 128}},
    {"ground", {165, 125, 85}},
    {"building", {255, 150, 60}},
    {"vegetation", {40, 180, 40}},
    {"vehicle", {30, 110, 255}},
    {"moving-vehicle", {255, 215, 0}},
    {"person", {255, 40, 200}},
    {"pole", {250, 240, 160}},
    {"fence", {170, 110, 220}},
    {"other", {0, 200, 200}},
    {"dynamic", {230, 30, 30}},
}};

}  // namespace

const char* ClassName(SemanticClass c) {
    const auto i = static_cast<size_t>(c);
    return i < kClasses.size() ? kClasses[i].name : kClasses[0].name;
}

Rgb ClassColor(SemanticClass c) {
    const auto i = static_cast<size_t>(c);
    return i < kClasses.size() ? kClasses[i].color : kClasses[0].color;
}

SemanticClass ClassFromName(const std::string& name) {
    for (size_t i = 0; i < kClasses.size(); ++i) {
        if (name == kClasses[i].name) return static_cast<SemanticClass>(i);
    }
    throw InvalidArgumentError("unknown semantic class '" + name + "'");
}

std::string LegendJson() {
    nlohmann::json legend = nlohmann::json::array();
    for (size_t i = 0; i < kClasses.size(); ++i) {
        const Rgb c = kClasses[i].color;
        legend.push_back({{"id", i}, {"name", kClasses[i].name}, {"color", {c.r, c.g, c.b}}});
    }
    return legend.dump();
}

LabelMapping LabelMapping::SemanticKitti() {
    using C = SemanticClass;
    LabelMapping m;
    for (uint32_t id : {0u, 1u}) m.Set(id, C::kUnknown);  // unlabeled, outlier
    for (uint32_t id : {10u, 13u, 15u, 16u, 18u, 20u}) m.Set(id, C::kVehicle);
    for (uint32_t id : {30u, 31u, 32u, 254u, 253u, 255u}) m.Set(id, C::kPerson);
    for (uint32_t id : {40u, 44u, 48u, 49u, 60u, 72u}) m.Set(id, C::kGround);
    for (uint32_t id : {50u, 52u}) m.Set(id, C::kBuilding);
    m.Set(51, C::kFence);
    for (uint32_t id : {70u, 71u}) m.Set(id, C::kVegetation);
    for (uint32_t id : {80u, 81u}) m.Set(id, C::kPole);
    for (uint32_t id : {252u, 256u, 257u, 258u, 259u}) m.Set(id, C::kMovingVehicle);
    m.Set(11, C::kOther);  // bicycle: not a vehicle the vehicle pipeline clears
    m.Set(99, C::kOther);
    return m;
}

LabelMapping LabelMapping::Las() {
    using C = SemanticClass;
    LabelMapping m;
    for (uint32_t id : {0u, 1u}) m.Set(id, C::kUnknown);  // never classified, unclassified
    for (uint32_t id : {2u, 11u}) m.Set(id, C::kGround);  // ground, road surface
    for (uint32_t id : {3u, 4u, 5u}) m.Set(id, C::kVegetation);
    m.Set(6, C::kBuilding);
    for (uint32_t id : {14u, 15u, 16u}) m.Set(id, C::kPole);  // wires and towers
    return m;
}

SemanticClass LabelMapping::Map(uint32_t raw_id) const {
    const auto it = table_.find(raw_id);
    if (it != table_.end()) return it->second;
    return raw_id == 0 ? SemanticClass::kUnknown : SemanticClass::kOther;
}

}  // namespace strata::core
