#pragma once
// `strata view MAP --html DIR`: the page and the data it shows as a folder that opens from disk.

#include <cstddef>
#include <filesystem>

#include "ViewService.hpp"

namespace strata::view {

/// What WriteStaticSite wrote.
struct StaticSiteReport {
    size_t files = 0;
    size_t bytes = 0;
    size_t diffs = 0;  ///< session pairs whose diff is included
};

/// Writes the page, three.js and every answer the page can ask for (the manifest, each pinned
/// tile version at every level of detail, the diff of each pair of consecutive sessions, the
/// saved change sets) as script files: a page opened from file:// may load scripts but not fetch
/// files. Voxel records and free-space slices need the server and are left out. The folder is
/// built beside `dir` and renamed into place, so `dir` is whole or absent.
/// @throw InvalidArgumentError when `dir` exists and is not an empty folder; IoError on a failed
/// write.
StaticSiteReport WriteStaticSite(const ViewService& service, const std::filesystem::path& dir);

}  // namespace strata::view
