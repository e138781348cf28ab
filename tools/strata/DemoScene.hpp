#pragma once

#include <filesystem>

namespace strata::tools {

/// Simulates the built-in demo street into a KITTI-layout sequence under `dir`; returns the
/// sequence folder.
[[nodiscard]] std::filesystem::path SimulateDemoStreet(const std::filesystem::path& dir);

}  // namespace strata::tools
