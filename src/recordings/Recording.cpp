#include "strata/recordings/Recording.hpp"

#include <cstdio>

#include "Ros1Bag.hpp"

namespace strata::recordings {

const Topic* RecordingInfo::Find(const std::string& name) const {
    for (const Topic& t : topics) {
        if (t.name == name) return &t;
    }
    return nullptr;
}

std::unique_ptr<Recording> Recording::Open(const std::filesystem::path& path) {
    return std::make_unique<detail::Ros1Bag>(path);
}

std::string FormatStamp(int64_t ns) {
    const bool negative = ns < 0;
    const uint64_t magnitude = negative ? 0 - static_cast<uint64_t>(ns) : static_cast<uint64_t>(ns);
    char text[48];
    std::snprintf(text, sizeof(text), "%s%llu.%09llu", negative ? "-" : "",
                  static_cast<unsigned long long>(magnitude / 1000000000u),
                  static_cast<unsigned long long>(magnitude % 1000000000u));
    return text;
}

}  // namespace strata::recordings
