#pragma once
// A 64-bit mix for values that must depend only on their key (never on threads or call order):
// the simulator's rays, the walls' seeds and ground sample.
#include <cstdint>

namespace strata::core {

/// @brief SplitMix64's finaliser: a bijective 64-bit mix with good avalanche.
[[nodiscard]] inline uint64_t Mix64(uint64_t x) {
    x += 0x9E3779B97F4A7C15ULL;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
    return x ^ (x >> 31);
}

}  // namespace strata::core
