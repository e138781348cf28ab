#pragma once

// Counter-based random numbers (private). A value depends only on its key, never on the thread
// or the order of calls, so simulations are reproducible for a given seed under TBB.
#include <cmath>
#include <cstdint>

#include "strata/core/Hash.hpp"

namespace strata::sim::detail {

using core::Mix64;

/// Key from several integers (seed, scan, ray, ...).
[[nodiscard]] inline uint64_t HashKey(uint64_t a, uint64_t b, uint64_t c = 0) {
    return Mix64(Mix64(Mix64(a) ^ b) ^ c);
}

/// A small sequential generator for building geometry (one per object, seeded by a key).
class Rng {
public:
    explicit Rng(uint64_t key) : state_(key) {}
    [[nodiscard]] uint64_t Next() { return Mix64(state_++); }
    /// Uniform in [0, 1) with 53 random bits.
    [[nodiscard]] double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
    [[nodiscard]] double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
    /// Standard normal (Box-Muller; one value per call).
    [[nodiscard]] double Normal() {
        const double u1 = 1.0 - Uniform();  // (0, 1]
        const double u2 = Uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
    }

private:
    uint64_t state_;
};

}  // namespace strata::sim::detail
