#pragma once
// Private to the integrator: LSD radix sort of keys below 2^key_bits, 11 bits per pass. Sorting a
// scan's endpoint keys this way is several times faster than a comparison sort.

#include <array>
#include <cstdint>
#include <vector>

namespace strata::integration::detail {

// `payload` (one value per key, or empty) is permuted along with the keys; the sort is stable.
// `key_buffer` and `payload_buffer` are scratch, kept by the caller from one sort to the next.
inline void RadixSort(std::vector<uint64_t>& keys, int key_bits, std::vector<uint32_t>& payload,
                      std::vector<uint64_t>& key_buffer, std::vector<uint32_t>& payload_buffer) {
    constexpr int kDigitBits = 11;
    constexpr size_t kBuckets = size_t{1} << kDigitBits;
    const bool carry = !payload.empty();
    key_buffer.resize(keys.size());
    payload_buffer.resize(carry ? keys.size() : 0);
    for (int shift = 0; shift < key_bits; shift += kDigitBits) {
        std::array<size_t, kBuckets> count{};
        for (const uint64_t k : keys) ++count[(k >> shift) & (kBuckets - 1)];
        size_t sum = 0;
        for (size_t& c : count) {
            const size_t here = c;
            c = sum;
            sum += here;
        }
        for (size_t i = 0; i < keys.size(); ++i) {
            const size_t to = count[(keys[i] >> shift) & (kBuckets - 1)]++;
            key_buffer[to] = keys[i];
            if (carry) payload_buffer[to] = payload[i];
        }
        keys.swap(key_buffer);
        if (carry) payload.swap(payload_buffer);
    }
}

}  // namespace strata::integration::detail
