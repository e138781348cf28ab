#pragma once
// bench_registration's second table: strata against the raw-point ICP on every real pair
// (docs/registration.md, "Real scans"), side by side in one run. Returns the number of pairs
// that miss the target, so the program exits non-zero on a miss.

#include <filesystem>

namespace strata::bench {

/// Prints the table (markdown rows) for the KITTI 00 and BALM pairs found under `data`.
/// @param repeat timings are the median of this many runs (one core).
[[nodiscard]] int PrintRegistrationPairs(const std::filesystem::path& data, int repeat);

}  // namespace strata::bench
