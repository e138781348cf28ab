#pragma once
// What a tile-by-tile use case budgets: memory, not file bytes (fused files are compressed).

#include <cstddef>
#include <string>

#include "strata/pipeline/Ranks.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::pipeline::detail {

/// @brief Memory per byte of fused file once a tile is decoded (at least 1), measured on the
/// snapshot's largest tile: the same on every rank.
[[nodiscard]] double MemoryPerFileByte(const store::MapStore& map, const store::Snapshot& snapshot);

/// @brief Whether the snapshot's fused tiles, decoded, fit `budget` bytes.
[[nodiscard]] bool FitsWhole(const store::MapStore& map, const store::Snapshot& snapshot,
                             size_t budget, double memory_per_file_byte);

/// @brief "12.34 MB": bytes in the budgets' messages.
[[nodiscard]] std::string Megabytes(double bytes);

/// @brief Rank 0's snapshot on every rank, though another process commits meanwhile (`snapshot`
/// is read on rank 0 only).
/// @throw the store's errors, on every rank.
[[nodiscard]] store::Snapshot SameSnapshotOnRanks(const store::MapStore& map,
                                                  const store::Snapshot& snapshot,
                                                  const Ranks& ranks);

}  // namespace strata::pipeline::detail
