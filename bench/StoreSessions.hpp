#pragma once
// bench_store, part 2 (docs/bench.md, Store): the same scans committed as sessions 1..N, what
// reading the current map reads, and the migration of a format-4 map. Each function prints its
// markdown table and returns the targets it missed (empty: all held).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "strata/core/Scan.hpp"

namespace strata::bench {

/// Bytes as MB (1e6), for the tables.
[[nodiscard]] double Mb(uint64_t bytes);

struct SessionsConfig {
    size_t sessions = 50;
    double voxel_m = 0.2;
    double tile_m = 64.0;
    /// Session N's commit CPU time over session 2's, at most (issue 17's target: 1.2).
    double max_time_ratio = 1.2;
};

/// Sessions 1..N of the same scans into one map: bytes and time per commit, disk use, the cost of
/// opening the current map; then a whole read of the current map by bytes read per kind.
[[nodiscard]] std::vector<std::string> BenchSessions(const std::vector<core::Scan>& scans,
                                                     const SessionsConfig& config,
                                                     const std::filesystem::path& tmp);

/// A map of `sessions` sessions rewritten as format 4, migrated by opening it as the writer:
/// time, and every session's snapshot and layers compared voxel by voxel.
[[nodiscard]] std::vector<std::string> BenchMigration(const std::vector<core::Scan>& scans,
                                                      size_t sessions, double voxel_m,
                                                      const std::filesystem::path& tmp);

}  // namespace strata::bench
