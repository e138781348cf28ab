#pragma once
// One session integrated by every rank of a command (docs/scale.md, "Integrate"): the same map,
// bit for bit, whatever the number of ranks.

#include <cstddef>
#include <functional>
#include <string>

#include "strata/core/Scan.hpp"
#include "strata/integration/IntegrationConfig.hpp"
#include "strata/pipeline/Ranks.hpp"
#include "strata/store/MapStore.hpp"
#include "strata/store/SessionWriter.hpp"

namespace strata::pipeline {

/// @brief The rank that keeps tile `key` among `ranks` ranks: (x + y) mod ranks, diagonals, so
/// that the tiles along a row or a column (a street's, a scan's neighbourhood) cycle through
/// every rank.
[[nodiscard]] int TileOwner(const store::TileKey& key, int ranks);

/// @brief What a ranked session wrote, summed over ranks.
struct RankedSessionResult {
    store::SessionRecord session;  ///< as committed (every rank gets it)
    store::WriterStats stats;      ///< summed over ranks (peak memory: the largest rank's)
    /// Where this rank's wall time went (docs/scale.md, "Measured here").
    struct Seconds {
        double cast = 0.0;      ///< reading its scans, casting their rays, cutting by owner
        double exchange = 0.0;  ///< in the exchanges: sending, and waiting for the other ranks
        double apply = 0.0;     ///< applying, in scan order, the parts that fall in its tiles
        double commit = 0.0;    ///< writing and syncing its files; on rank 0 the commit too
    } seconds;
};

/// Scans a rank casts per round of IntegrateOnRanks: the ranks wait for each other once per
/// round, so one slow scan is averaged over a block (docs/scale.md, "Measured here").
inline constexpr size_t kScansPerBlock = 8;

/// @brief Integrates scans 0..scans-1 as one session of `map` on every rank of `ranks`: in
/// rounds of N blocks of `scans_per_block` consecutive scans, rank r reads and computes the
/// updates of the round's r-th block; each update is cut by tile owner and every rank applies,
/// in scan order, the parts in its own tiles; rank 0 commits every rank's files in one
/// transaction once all are synced (and its own written meanwhile). Every rank calls it with the
/// same arguments; `map` is open for writing on rank 0 (first) and for reading on the others
/// (OpenOnRanks). `progress` (may be empty) is called on rank 0 with the number of scans done.
/// @throw what any rank threw, on every rank ("rank K: ..." when another rank's); the map then
/// stays at its last commit.
RankedSessionResult IntegrateOnRanks(store::MapStore& map, size_t scans,
                                     const std::function<core::Scan(size_t)>& read,
                                     const integration::IntegrationConfig& config,
                                     store::SessionOptions options, const Ranks& ranks,
                                     const std::function<void(size_t)>& progress = {},
                                     size_t scans_per_block = kScansPerBlock);

/// @brief Opens the map on every rank: `open_root` on rank 0 (for writing; it may create or
/// migrate the map), then `dir` for reading on the others once rank 0 succeeded.
/// @throw what rank 0 threw, on every rank.
[[nodiscard]] store::MapStore OpenOnRanks(const std::filesystem::path& dir, const Ranks& ranks,
                                          const std::function<store::MapStore()>& open_root);

/// @brief Runs `step` on every rank; if it throws on any, every rank throws: its own error, or
/// "rank K: <message>" of the lowest failing rank, of the same kind where the kind is known.
void OnEveryRank(const Ranks& ranks, const std::function<void()>& step);

}  // namespace strata::pipeline
