#include "TileBudget.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>

#include "strata/pipeline/RankedSession.hpp"

namespace strata::pipeline::detail {

double MemoryPerFileByte(const store::MapStore& map, const store::Snapshot& snapshot) {
    const auto largest = std::max_element(
        snapshot.tiles.begin(), snapshot.tiles.end(),
        [](const store::TileVersion& a, const store::TileVersion& b) { return a.bytes < b.bytes; });
    if (largest == snapshot.tiles.end() || largest->bytes == 0) return 1.0;
    size_t memory = 0;
    for (const auto& grid : map.ReadFused(*largest).Grids()) memory += grid->memUsage();
    return std::max(1.0, static_cast<double>(memory) / static_cast<double>(largest->bytes));
}

std::string Megabytes(double bytes) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.2f MB", bytes / 1e6);
    return text;
}

bool FitsWhole(const store::MapStore& map, const store::Snapshot& snapshot, size_t budget,
               double memory_per_file_byte) {
    return static_cast<double>(map.Bytes(snapshot).fused_current) * memory_per_file_byte <=
           static_cast<double>(budget);
}

store::Snapshot SameSnapshotOnRanks(const store::MapStore& map, const store::Snapshot& snapshot,
                                    const Ranks& ranks) {
    const int64_t commit = std::stoll(ranks.Broadcast(std::to_string(snapshot.commit)));
    std::optional<store::Snapshot> same;
    OnEveryRank(ranks, [&] { same = ranks.root() ? snapshot : map.At(commit); });
    return *same;
}

}  // namespace strata::pipeline::detail
