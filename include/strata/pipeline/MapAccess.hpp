#pragma once
// How a stored map is opened and which snapshot a read shows: the same for `strata` and Python.

#include <filesystem>
#include <string>

#include "strata/store/MapStore.hpp"

namespace strata::pipeline {

/// @brief Opens the map in `dir` for reading (or as its writer).
/// @throw NotFoundError, saying how to create a map, when `dir` does not exist; the store's
/// errors otherwise (MapLockedError, FormatError, ...).
[[nodiscard]] store::MapStore OpenMap(
    const std::filesystem::path& dir,
    store::MapStore::Access access = store::MapStore::Access::kRead);

/// @brief The commit a read shows: the newest, or the one right after session `as_of` (an id
/// or a name) when it is not empty (NotFoundError listing the sessions otherwise).
[[nodiscard]] store::Snapshot SelectSnapshot(const store::MapStore& map, const std::string& as_of);

/// @brief Checks that products computed from the snapshot of `commit` may be stored: `map` is
/// open for writing and `commit` is its newest commit (`what` names the products).
/// @throw InvalidArgumentError otherwise, saying which.
void RequireNewest(const store::MapStore& map, int64_t commit, const std::string& what);

}  // namespace strata::pipeline
