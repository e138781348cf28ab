#include "strata/recordings/Recording.hpp"

#include <algorithm>
#include <cstdio>

#include "Mcap.hpp"
#include "Ros1Bag.hpp"
#include "Rosbag2Sqlite.hpp"
#include "strata/core/Error.hpp"

namespace strata::recordings {

const Topic* RecordingInfo::Find(const std::string& name) const {
    for (const Topic& t : topics) {
        if (t.name == name) return &t;
    }
    return nullptr;
}

std::unique_ptr<Recording> Recording::Open(const std::filesystem::path& path) {
    // By content, not by name: a `.bag` may be either (ros2 bag's MCAP files are often renamed).
    if (std::filesystem::is_directory(path)) return std::make_unique<detail::Rosbag2Sqlite>(path);
    std::vector<uint8_t> first;
    {
        const detail::FileReader file(path);
        file.Read(0, std::min<uint64_t>(file.size(), 16), first, "first bytes");
    }
    const std::string start(first.begin(), first.end());
    if (start.rfind("#ROSBAG", 0) == 0) return std::make_unique<detail::Ros1Bag>(path);
    if (start.size() >= 5 && start.compare(1, 4, "MCAP") == 0 && first[0] == 0x89) {
        return std::make_unique<detail::Mcap>(path);
    }
    if (start == std::string("SQLite format 3\0", 16)) {
        return std::make_unique<detail::Rosbag2Sqlite>(path);
    }
    throw FormatError(path.string() +
                      ": not a recording strata reads (a ROS 1 bag, an MCAP file or a rosbag2 "
                      ".db3 file, by its first bytes; or a rosbag2 folder)");
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
