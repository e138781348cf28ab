#pragma once
// Shared by subcommands: where data lives and how a map is opened.

#include <filesystem>
#include <string>

#include "strata/io/MapIo.hpp"

namespace strata::tools {

/// The real-data folder: $STRATA_DATA_DIR, else ../shared/data from the working directory or
/// from the executable's source checkout. Empty when none exists.
[[nodiscard]] std::filesystem::path FindDataDir();

/// Loads MAP, failing with a message that says how to create one.
[[nodiscard]] io::MapDirectory OpenMap(const std::filesystem::path& dir);

/// Current UTC time as ISO 8601.
[[nodiscard]] std::string UtcNow();

}  // namespace strata::tools
