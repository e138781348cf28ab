#pragma once
// Private to the integrator: LSD radix sort of keys below 2^key_bits, 11 bits per pass. Sorting a
// scan's endpoint keys this way is several times faster than a comparison sort.

#include <array>
#include <cstdint>
#include <vector>

namespace strata::integration::detail {

inline void RadixSort(std::vector<uint64_t>& keys, int key_bits) {
    constexpr int kDigitBits = 11;
    constexpr size_t kBuckets = size_t{1} << kDigitBits;
    std::vector<uint64_t> buffer(keys.size());
    for (int shift = 0; shift < key_bits; shift += kDigitBits) {
        std::array<size_t, kBuckets> count{};
        for (const uint64_t k : keys) ++count[(k >> shift) & (kBuckets - 1)];
        size_t sum = 0;
        for (size_t& c : count) {
            const size_t here = c;
            c = sum;
            sum += here;
        }
        for (const uint64_t k : keys) buffer[count[(k >> shift) & (kBuckets - 1)]++] = k;
        keys.swap(buffer);
    }
}

}  // namespace strata::integration::detail
