#include "OctomapCompare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "VoxelSets.hpp"

namespace strata::testing {
namespace {

using KeyValue = std::pair<uint64_t, float>;  // packed key, log-odds

std::vector<KeyValue> StrataValues(const core::VoxelMap& map) {
    std::vector<KeyValue> out;
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (!it.isVoxelValue()) {  // an active tile: every voxel under it
            openvdb::CoordBBox box;
            it.getBoundingBox(box);
            for (const openvdb::Coord& c : box) out.emplace_back(PackKey(c.x(), c.y(), c.z()), *it);
            continue;
        }
        const openvdb::Coord c = it.getCoord();
        out.emplace_back(PackKey(c.x(), c.y(), c.z()), *it);
    }
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<KeyValue> OctomapValues(const octomap::OcTree& tree) {
    std::vector<KeyValue> out;
    const int depth = static_cast<int>(tree.getTreeDepth());
    constexpr int32_t kOffset = 32768;  // OctoMap's tree_max_val at depth 16
    for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
        const int32_t n = 1 << (depth - static_cast<int>(it.getDepth()));
        const octomap::OcTreeKey k = it.getIndexKey();
        const float v = it->getLogOdds();
        for (int32_t dx = 0; dx < n; ++dx) {
            for (int32_t dy = 0; dy < n; ++dy) {
                for (int32_t dz = 0; dz < n; ++dz) {
                    out.emplace_back(
                        PackKey(k[0] - kOffset + dx, k[1] - kOffset + dy, k[2] - kOffset + dz), v);
                }
            }
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

std::string Describe(uint64_t key, const char* what, float ours, float theirs) {
    constexpr int64_t kBias = int64_t{1} << 20;
    const auto axis = [&](int shift) {
        return static_cast<int64_t>((key >> shift) & 0x1fffff) - kBias;
    };
    char text[160];
    std::snprintf(text, sizeof(text), "(%lld, %lld, %lld) %s: strata %.4f, OctoMap %.4f",
                  static_cast<long long>(axis(42)), static_cast<long long>(axis(21)),
                  static_cast<long long>(axis(0)), what, static_cast<double>(ours),
                  static_cast<double>(theirs));
    return text;
}

}  // namespace

MapDifferences CompareWithOctomap(const core::VoxelMap& map, const octomap::OcTree& tree,
                                  float tolerance) {
    constexpr size_t kExamples = 10;
    constexpr float kUnknown = std::numeric_limits<float>::quiet_NaN();
    const std::vector<KeyValue> ours = StrataValues(map);
    const std::vector<KeyValue> theirs = OctomapValues(tree);
    MapDifferences d;
    d.voxels_ours = ours.size();
    d.voxels_theirs = theirs.size();
    const auto note = [&](uint64_t key, const char* what, float a, float b) {
        if (d.examples.size() < kExamples) d.examples.push_back(Describe(key, what, a, b));
    };
    size_t i = 0, j = 0;
    while (i < ours.size() || j < theirs.size()) {
        if (j == theirs.size() || (i < ours.size() && ours[i].first < theirs[j].first)) {
            ++d.only_ours;
            note(ours[i].first, "only in strata", ours[i].second, kUnknown);
            ++i;
        } else if (i == ours.size() || theirs[j].first < ours[i].first) {
            ++d.only_theirs;
            note(theirs[j].first, "only in OctoMap", kUnknown, theirs[j].second);
            ++j;
        } else {
            const float a = ours[i].second, b = theirs[j].second;
            const double diff = std::fabs(static_cast<double>(a) - static_cast<double>(b));
            d.max_log_odds_difference = std::max(d.max_log_odds_difference, diff);
            if ((a > 0.0f) != (b > 0.0f)) {
                ++d.state_differs;
                note(ours[i].first, "state differs", a, b);
            } else if (diff > tolerance) {
                ++d.log_odds_differs;
                note(ours[i].first, "log-odds differ", a, b);
            }
            ++i;
            ++j;
        }
    }
    return d;
}

}  // namespace strata::testing
