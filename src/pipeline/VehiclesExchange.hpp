#pragma once
// What a rank found of the vehicles (pipeline::ClearVehiclesOnRanks), in bytes for rank 0
// (docs/scale.md), written and read with core/Bytes.hpp.

#include <cstddef>
#include <string>
#include <vector>

#include "strata/vehicles/VehicleStages.hpp"

namespace strata::pipeline::detail {

/// @brief The blocks a rank cleared and the measured ground columns of their cores.
[[nodiscard]] std::string EncodeWindows(const std::vector<vehicles::WindowVehicles>& found,
                                        size_t ground_columns);
/// @brief One rank's EncodeWindows: its blocks, in its order; its ground columns are added to
/// `ground_columns`.
/// @throw FormatError when the bytes are cut short.
[[nodiscard]] std::vector<vehicles::WindowVehicles> DecodeWindows(const std::string& bytes,
                                                                  size_t& ground_columns);

/// @brief The long objects' samples of a rank's windows.
[[nodiscard]] std::string EncodeSamples(const std::vector<vehicles::ObjectSample>& samples);
/// @throw FormatError when the bytes are cut short.
[[nodiscard]] std::vector<vehicles::ObjectSample> DecodeSamples(const std::string& bytes);

/// @brief The long objects' vehicles, from rank 0 to every rank.
[[nodiscard]] std::string EncodeLongObjects(const vehicles::LongObjects& long_objects);
/// @throw FormatError when the bytes are cut short.
[[nodiscard]] vehicles::LongObjects DecodeLongObjects(const std::string& bytes);

}  // namespace strata::pipeline::detail
