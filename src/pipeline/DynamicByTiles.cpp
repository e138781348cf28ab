// Moving things out of a map a tile at a time. A candidate's verdict needs the space crossed
// within the margin around it, which a tile and its eight neighbours hold; the objects need every
// removed voxel, few enough to gather before they are grouped (docs/dynamic.md, "Tile by tile").
#include "DynamicByTiles.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "TileBudget.hpp"
#include "strata/core/Bytes.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/RankedSession.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::core {
template <>
struct Fields<dynamic::VoxelVerdicts> {
    template <typename Io, typename V>
    static void Visit(Io& io, V& v) {
        io(v.removed, v.occupied, v.restored, v.occupied_voxels);
    }
};
}  // namespace strata::core

namespace strata::pipeline::detail {
namespace {

// Removed voxels and a session whose points ended in each.
using HitBy = std::vector<std::pair<openvdb::Coord, int64_t>>;

// The verdicts of every rank on rank 0, in rank order (the others keep theirs).
void GatherOnRoot(const Ranks& ranks, dynamic::VoxelVerdicts& verdicts, HitBy& hit_by) {
    std::string bytes;
    core::Put(bytes, verdicts);
    core::Put(bytes, hit_by);
    const std::vector<std::string> all = ranks.Gather(bytes);
    if (!ranks.root()) return;
    verdicts = {};
    hit_by.clear();
    for (const std::string& answer : all) {
        core::ByteReader in(answer, "dynamic: a rank's verdicts");
        verdicts.Append(in.Get<dynamic::VoxelVerdicts>());
        const HitBy part = in.Get<HitBy>();
        hit_by.insert(hit_by.end(), part.begin(), part.end());
    }
}

// The verdicts on the tiles this rank owns (TileOwner) and who hit each removed voxel.
void JudgeTiles(const store::MapStore& map, const store::Snapshot& snapshot,
                const dynamic::DynamicConfig& config, int64_t session, size_t budget,
                const DecodedBytes& decoded, const Ranks& ranks, dynamic::VoxelVerdicts& verdicts,
                HitBy& hit_by) {
    std::map<store::TileKey, std::vector<int64_t>> sessions_in;  // the layers of each tile
    std::map<store::TileKey, uint64_t> layer_bytes;
    for (const store::LayerFile& l : snapshot.layers) {
        sessions_in[l.key].push_back(l.session);
        layer_bytes[l.key] += l.bytes;
    }
    const auto window = [](const store::TileKey& k) {
        std::vector<store::TileKey> keys;
        for (int dx = -1; dx <= 1; ++dx) {
            for (int dy = -1; dy <= 1; ++dy) keys.push_back({k.x + dx, k.y + dy});
        }
        return keys;
    };
    // What a tile's turn holds in memory: its fused grids and its window's layers, decoded.
    double largest = 0.0;
    for (const store::TileVersion& t : snapshot.tiles) {
        double bytes = static_cast<double>(t.bytes) * decoded.per_fused_byte;
        for (const store::TileKey& k : window(t.key)) {
            const auto it = layer_bytes.find(k);
            if (it != layer_bytes.end())
                bytes += static_cast<double>(it->second) * decoded.per_layer_byte;
        }
        largest = std::max(largest, bytes);
    }
    if (budget > 0 && 2.0 * largest > static_cast<double>(budget)) {
        throw RefusedError(map.dir().string() +
                           ": a tile with the session layers of its eight neighbours takes about " +
                           Megabytes(largest) + " in memory, more than half the memory budget of " +
                           Megabytes(static_cast<double>(budget)) +
                           " (the other half keeps tiles read for their neighbours' turns); "
                           "raise --memory-budget");
    }

    const store::TileReader reader(
        map, snapshot, budget > 0 ? budget / 2 : store::TileReader::kDefaultBudgetBytes);
    for (const store::TileVersion& t : snapshot.tiles) {
        if (TileOwner(t.key, ranks.size()) != ranks.rank()) continue;
        const auto fused = reader.Fused(t.key);
        dynamic::SeenSpace seen{openvdb::MaskGrid::create(), openvdb::MaskGrid::create()};
        std::map<int64_t, openvdb::MaskTree> hits;  // in this tile, by session
        for (const store::TileKey& k : window(t.key)) {
            for (const int64_t s : sessions_in[k]) {
                const auto layer = reader.Layers(k, s);
                if (!layer) continue;
                seen.crossed->tree().topologyUnion(CrossedBy(*layer, snapshot));
                if (k != t.key) continue;
                openvdb::MaskTree& hit = hits[s];
                hit.topologyUnion(layer->occupied->tree());
                hit.topologyUnion(layer->hit->tree());
            }
        }
        for (const auto& [id, hit] : hits) {
            if (session == 0 || id == session) seen.hit->tree().topologyUnion(hit);
        }
        dynamic::VoxelVerdicts part = dynamic::JudgeVoxels(*fused, seen, config);
        for (const auto& [id, hit] : hits) {
            for (const openvdb::Coord& c : part.removed) {
                if (hit.isValueOn(c)) hit_by.emplace_back(c, id);
            }
        }
        verdicts.Append(std::move(part));
    }
}

}  // namespace

DecodedBytes MeasureDecoded(const store::MapStore& map, const store::Snapshot& snapshot) {
    DecodedBytes decoded;
    decoded.per_fused_byte = MemoryPerFileByte(map, snapshot);
    const auto largest = std::max_element(
        snapshot.layers.begin(), snapshot.layers.end(),
        [](const store::LayerFile& a, const store::LayerFile& b) { return a.bytes < b.bytes; });
    if (largest == snapshot.layers.end() || largest->bytes == 0) return decoded;
    const store::SessionLayer layer = map.ReadLayer(*largest);
    size_t memory = 0;
    for (const auto* grid :
         {&layer.occupied, &layer.free, &layer.crossed, &layer.grazed, &layer.hit}) {
        if (*grid) memory += (*grid)->memUsage();
    }
    decoded.per_layer_byte =
        std::max(1.0, static_cast<double>(memory) / static_cast<double>(largest->bytes));
    return decoded;
}

bool DynamicFitsWhole(const store::MapStore& map, const store::Snapshot& snapshot, size_t budget,
                      const DecodedBytes& decoded) {
    double layers = 0.0;
    for (const store::LayerFile& l : snapshot.layers) layers += static_cast<double>(l.bytes);
    const double fused = static_cast<double>(map.Bytes(snapshot).fused_current);
    return fused * decoded.per_fused_byte + layers * decoded.per_layer_byte <=
           static_cast<double>(budget);
}

void RequireCrossed(const store::SessionLayer& layer, const store::Snapshot& snapshot) {
    if (!layer.crossed || !layer.grazed || !layer.hit) {
        const auto s = std::find_if(snapshot.sessions.begin(), snapshot.sessions.end(),
                                    [&](const auto& r) { return r.id == layer.session; });
        const std::string name = s == snapshot.sessions.end() ? "" : " '" + s->name + "'";
        throw RefusedError("session " + std::to_string(layer.session) + name +
                           " was integrated before strata recorded the space its rays crossed "
                           "(map format 6): integrate its scans again (`strata remove-session`, "
                           "then `strata integrate`) to find what moved");
    }
}

openvdb::MaskTree CrossedBy(const store::SessionLayer& layer, const store::Snapshot& snapshot) {
    RequireCrossed(layer, snapshot);
    openvdb::MaskTree through(layer.free->tree(), false, openvdb::TopologyCopy());
    through.topologyDifference(layer.grazed->tree());
    through.topologyUnion(layer.crossed->tree());
    return through;
}

DynamicOutcome FindDynamicByTiles(const store::MapStore& map, const store::Snapshot& snapshot,
                                  const dynamic::DynamicConfig& config, int64_t session,
                                  size_t budget, const DecodedBytes& decoded, const Ranks& ranks) {
    dynamic::VoxelVerdicts verdicts;
    HitBy hit_by;
    OnEveryRank(ranks, [&] {
        JudgeTiles(map, snapshot, config, session, budget, decoded, ranks, verdicts, hit_by);
    });
    if (ranks.size() > 1) GatherOnRoot(ranks, verdicts, hit_by);
    DynamicOutcome out;
    out.commit = snapshot.commit;
    out.config = config;
    out.session = session;
    out.tiles = snapshot.tiles.size();
    if (!ranks.root()) return out;
    const core::VoxelMap empty = map.EmptyMap();
    out.result = dynamic::GroupVerdicts(std::move(verdicts), empty.occupancy->transform(),
                                        empty.voxel_size, config);
    std::vector<std::set<int64_t>> seen_by(out.result.objects.size());
    const auto ids = out.result.removed->getConstAccessor();
    for (const auto& [c, id] : hit_by) {
        const int32_t object = ids.getValue(c);
        if (object > 0) seen_by[static_cast<size_t>(object - 1)].insert(id);
    }
    for (const std::set<int64_t>& s : seen_by) out.object_sessions.emplace_back(s.begin(), s.end());
    return out;
}

}  // namespace strata::pipeline::detail
