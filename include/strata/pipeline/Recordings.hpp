#pragma once
// What a robot recording holds, as `strata bag info` and Python describe it (docs/recordings.md).

#include <filesystem>
#include <nlohmann/json.hpp>

namespace strata::pipeline {

/// @brief The recording's format, size, compression, span, topics (type, encoding, message count)
/// and its tf tree's frames and edges (static or with their sample count and span), as JSON.
/// @throw the recording's errors (recordings::Recording::Open, Read).
[[nodiscard]] nlohmann::json DescribeRecording(const std::filesystem::path& path);

}  // namespace strata::pipeline
