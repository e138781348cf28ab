#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "strata/core/VoxelMap.hpp"

namespace strata::io {

/// @brief One integration run recorded in a map.
struct MapSession {
    int id = 0;
    std::string name;
    std::string source;       ///< sequence folder or first scan file
    size_t scans = 0;
    size_t points = 0;
    std::string created_utc;  ///< ISO 8601
};

/// @brief A map directory: `MAP/map.vdb` holds every grid and, as file metadata, the sessions.
/// One file, replaced by an atomic rename, so a failed command never leaves a damaged map.
/// @note This is the interim single-file layout; the tiled store (catalog.sqlite + tiles/)
/// replaces it behind the same command line.
struct MapDirectory {
    core::VoxelMap map;
    std::vector<MapSession> sessions;
};

/// @brief Path of the grid file inside a map directory.
[[nodiscard]] std::filesystem::path MapGridFile(const std::filesystem::path& dir);
/// @brief True when `dir` holds a map.
[[nodiscard]] bool IsMapDirectory(const std::filesystem::path& dir);
/// @brief Reads a map; throws std::runtime_error naming the file and the problem.
[[nodiscard]] MapDirectory LoadMapDirectory(const std::filesystem::path& dir);
/// @brief Writes a map (creating `dir`): temporary file, checked stream, fsync, rename.
void SaveMapDirectory(const MapDirectory& map, const std::filesystem::path& dir);

}  // namespace strata::io
