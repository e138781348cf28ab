#include "strata/core/FrameRange.hpp"

#include <stdexcept>

#include "strata/core/Error.hpp"

namespace strata::core {

std::pair<size_t, size_t> ParseFrameRange(const std::string& text, size_t n) {
    if (text.empty()) return {0, n};
    try {
        const auto colon = text.find(':');
        if (colon == std::string::npos) {
            const size_t a = std::stoul(text);
            if (a < n) return {a, a + 1};
            throw std::out_of_range(text);
        }
        const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
        const size_t begin = a.empty() ? 0 : std::stoul(a);
        const size_t end = b.empty() ? n : std::stoul(b);
        if (begin < end && end <= n) return {begin, end};
    } catch (const std::logic_error&) {
    }
    throw InvalidArgumentError("--frames '" + text +
                               "': expected A:B with 0 <= A < B <= " + std::to_string(n));
}

}  // namespace strata::core
