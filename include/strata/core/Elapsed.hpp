#pragma once
// Wall time since a moment, for the stats and timings the stages report (WriterStats, --profile,
// the walls' and vehicles' seconds).

#include <chrono>

namespace strata::core {

using Clock = std::chrono::steady_clock;

/// @brief Seconds from `start` to now.
inline double SecondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace strata::core
