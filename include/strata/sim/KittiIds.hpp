#pragma once

#include <cstdint>
#include <string>

#include "strata/core/Labels.hpp"

/// @brief SemanticKITTI raw class ids, as the simulator writes them into `.label` files
/// (low 16 bits; the high 16 bits hold the instance id).
namespace strata::sim::kitti {

inline constexpr uint16_t kUnlabeled = 0;
inline constexpr uint16_t kCar = 10;
inline constexpr uint16_t kBus = 13;
inline constexpr uint16_t kTruck = 18;
inline constexpr uint16_t kOtherVehicle = 20;
inline constexpr uint16_t kPerson = 30;
inline constexpr uint16_t kBicyclist = 31;
inline constexpr uint16_t kRoad = 40;
inline constexpr uint16_t kParking = 44;
inline constexpr uint16_t kSidewalk = 48;
inline constexpr uint16_t kOtherGround = 49;
inline constexpr uint16_t kBuilding = 50;
inline constexpr uint16_t kFence = 51;
inline constexpr uint16_t kOtherStructure = 52;
inline constexpr uint16_t kLaneMarking = 60;
inline constexpr uint16_t kVegetation = 70;
inline constexpr uint16_t kTrunk = 71;
inline constexpr uint16_t kTerrain = 72;
inline constexpr uint16_t kPole = 80;
inline constexpr uint16_t kTrafficSign = 81;
inline constexpr uint16_t kOtherObject = 99;
// Moving things (traffic): SemanticKITTI's moving classes.
inline constexpr uint16_t kMovingCar = 252;
inline constexpr uint16_t kMovingBicyclist = 253;
inline constexpr uint16_t kMovingPerson = 254;
inline constexpr uint16_t kMovingTruck = 258;

/// @brief Raw id of a SemanticKITTI class name ("car", "road", "other-structure", ...) or of a
/// decimal id given as text ("44"); throws InvalidArgumentError for anything else.
[[nodiscard]] uint16_t IdFromName(const std::string& name);
/// @brief SemanticKITTI name of a raw id ("car"); "unknown" for ids the simulator never writes.
[[nodiscard]] const char* Name(uint16_t id);
/// @brief Display colour of a raw id for top-down pictures (finer than core::ClassColor: road,
/// sidewalk, parking and lane markings differ).
[[nodiscard]] core::Rgb Color(uint16_t id);
/// @brief True for classes that vehicles stand on (road, parking, sidewalk, other-ground,
/// lane marking, terrain).
[[nodiscard]] bool IsGround(uint16_t id);

}  // namespace strata::sim::kitti
