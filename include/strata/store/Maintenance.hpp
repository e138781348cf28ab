#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace strata::store {

/// @brief One problem `MapStore::Check` found.
struct CheckProblem {
    std::string file;  ///< relative to the map directory
    std::string what;
};

struct CheckReport {
    size_t files = 0;  ///< referenced files checked (fused versions, layers, products)
    std::vector<CheckProblem> problems;
    std::vector<std::string> unreferenced;  ///< files `CollectGarbage` would remove
    [[nodiscard]] bool ok() const { return problems.empty(); }
};

/// @brief Which history `MapStore::DropHistory` keeps: the snapshots of the last `keep_last`
/// commits, or of every commit since `keep_since_utc` (ISO 8601, e.g. "2024-06-01" or
/// "2024-06-01T12:00:00Z") together with the snapshot that was current then. Exactly one is set.
struct HistoryPolicy {
    int64_t keep_last = 0;
    std::string keep_since_utc;
    /// @brief Throws InvalidArgumentError unless exactly one field is set and it is valid.
    void Validate() const;
};

struct GcReport {
    std::vector<std::string> removed;  ///< files removed, relative to the map
    uint64_t bytes = 0;
    int64_t history_start = 0;  ///< the oldest commit whose snapshot is kept afterwards
};

/// @brief Bytes of a map's files by kind (the catalog's record of them).
struct StorageBytes {
    uint64_t fused_current = 0;  ///< fused versions of the snapshot asked about
    uint64_t fused_older = 0;    ///< every other fused version kept (history)
    uint64_t layers = 0;         ///< every session layer file kept
    uint64_t products = 0;       ///< every product file kept
};

/// @brief Bytes of verified files the store read in this process, by kind (every read of a
/// fused, layer or product file counts, cache misses only when read through a TileReader).
struct ReadCounters {
    uint64_t fused = 0;
    uint64_t layers = 0;
    uint64_t products = 0;
    uint64_t files = 0;
};
/// @brief The process-wide totals so far (thread-safe).
[[nodiscard]] ReadCounters BytesRead();

}  // namespace strata::store
