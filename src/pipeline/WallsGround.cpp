#include "WallsGround.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <string>
#include <utility>

#include "strata/columns/ColumnStats.hpp"
#include "strata/core/Bytes.hpp"
#include "strata/pipeline/RankedSession.hpp"

namespace strata::pipeline::detail {

namespace {

using Entry = walls::GroundSample::Entry;

// The sample of `tiles`, a few tiles in parallel at a time: the sample takes its columns one by
// one, and which it keeps does not depend on the order they come in.
walls::GroundSample SampleTiles(const store::TileReader& reader,
                                const std::vector<store::TileKey>& tiles) {
    constexpr size_t kTilesAtOnce = 8;
    const store::MapSettings& settings = reader.settings();
    walls::GroundSample sample;
    for (size_t at = 0; at < tiles.size(); at += kTilesAtOnce) {
        const size_t n = std::min(kTilesAtOnce, tiles.size() - at);
        std::vector<std::vector<std::pair<openvdb::Coord, Eigen::Vector3d>>> lowest(n);
        // Admits only reads the sample, which nothing changes until the tiles are done.
        tbb::parallel_for(size_t{0}, n, [&](size_t t) {
            const auto tile = reader.Fused(tiles[at + t]);
            if (!tile) return;
            const openvdb::CoordBBox box = settings.TileBounds(tiles[at + t]);
            const columns::ColumnGrid cols = columns::ColumnGrid::FromMap(*tile, box);
            for (int32_t j = box.min().y(); j <= box.max().y(); ++j) {
                for (int32_t i = box.min().x(); i <= box.max().x(); ++i) {
                    const columns::ColumnStat& c = cols.At(i, j);
                    if (c.voxels == 0 || !sample.Admits(i, j)) continue;
                    lowest[t].emplace_back(openvdb::Coord(i, j, c.k_min),
                                           tile->PointMean(openvdb::Coord(i, j, c.k_min)));
                }
            }
        });
        for (const auto& columns : lowest) {
            for (const auto& [c, mean] : columns) sample.Add(c.x(), c.y(), mean);
        }
    }
    return sample;
}

}  // namespace

walls::GroundPlane GroundByTiles(const store::TileReader& reader,
                                 const std::vector<store::TileKey>& tiles, uint64_t seed,
                                 const Ranks& ranks) {
    walls::GroundSample sample;
    OnEveryRank(ranks, [&] { sample = SampleTiles(reader, tiles); });
    if (ranks.size() > 1) {
        // Rank 0 merges every rank's sample and sends the merged one back: each rank fits the
        // plane itself, with the same seed, so every rank has the same plane.
        std::string bytes;
        core::PutVector(bytes, sample.entries());
        const std::vector<std::string> all = ranks.Gather(bytes);
        std::string merged;
        if (ranks.root()) {
            for (size_t r = 1; r < all.size(); ++r) {
                core::ByteReader in(all[r], "walls ground sample");
                for (const Entry& e : in.GetVector<Entry>()) sample.Add(e);
            }
            core::PutVector(merged, sample.entries());
        }
        merged = ranks.Broadcast(merged);
        if (!ranks.root()) {
            sample = walls::GroundSample();
            core::ByteReader in(merged, "walls ground sample");
            for (const Entry& e : in.GetVector<Entry>()) sample.Add(e);
        }
    }
    return walls::FitGround(sample, reader.settings().voxel_size_m, seed);
}

}  // namespace strata::pipeline::detail
