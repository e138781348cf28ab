#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <unordered_map>

namespace strata::core {

/// @brief strata's semantic classes. Values are stored in the `label` grid, so never renumber them.
enum class SemanticClass : uint8_t {
    kUnknown = 0,
    kGround,
    kBuilding,
    kVegetation,
    kVehicle,
    kMovingVehicle,
    kPerson,
    kPole,
    kFence,
    kOther,
    kDynamic,  ///< held something that moved (docs/dynamic.md): set by `strata dynamic`
};
inline constexpr int kNumClasses = 11;

struct Rgb {
    uint8_t r, g, b;
};

/// @brief Lower-case name of a class ("vehicle"); "unknown" for out-of-range values.
[[nodiscard]] const char* ClassName(SemanticClass c);
/// @brief Display colour of a class (used by PNG, PLY, OctoMap and VDB colour exports).
[[nodiscard]] Rgb ClassColor(SemanticClass c);
/// @brief Parses a class name as printed by ClassName; throws InvalidArgumentError otherwise.
[[nodiscard]] SemanticClass ClassFromName(const std::string& name);
/// @brief The legend as a JSON array [{"id":..,"name":..,"color":[r,g,b]}], stored in grid
/// metadata.
[[nodiscard]] std::string LegendJson();

/// @brief Maps the raw class ids of a source format to SemanticClass. Unmapped ids map to kOther
/// (kUnknown for id 0, "unlabelled" in both SemanticKITTI and LAS).
class LabelMapping {
public:
    LabelMapping() = default;
    /// @brief SemanticKITTI ids (10 car, 40 road, 50 building, 70 vegetation, 252-259 moving ...).
    [[nodiscard]] static LabelMapping SemanticKitti();
    /// @brief ASPRS LAS classification codes (2 ground, 3-5 vegetation, 6 building, ...).
    [[nodiscard]] static LabelMapping Las();

    void Set(uint32_t raw_id, SemanticClass c) { table_[raw_id] = c; }
    [[nodiscard]] SemanticClass Map(uint32_t raw_id) const;

private:
    std::unordered_map<uint32_t, SemanticClass> table_;
};

}  // namespace strata::core
