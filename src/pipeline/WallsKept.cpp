// walls' stage 1 per group of tiles keeps a WallsKept; under mpirun each rank sends its own to
// rank 0 as bytes: the counts and columns as flat records (core/Bytes.hpp), the grids as one
// OpenVDB stream.
#include "WallsKept.hpp"

#include <openvdb/io/Stream.h>

#include <algorithm>
#include <sstream>

#include "strata/core/Bytes.hpp"
#include "strata/core/Error.hpp"

namespace strata::pipeline::detail {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;

constexpr const char* kObservedFreeGrid = "observed_free";

// Copies every voxel `from` holds (active, or inactive with a value of its own) into `into`.
template <typename GridT>
void MergeVoxels(const GridT& from, GridT& into) {
    const auto background = from.background();
    auto acc = into.getAccessor();
    for (auto leaf = from.tree().cbeginLeaf(); leaf; ++leaf) {
        for (auto v = leaf->cbeginValueAll(); v; ++v) {
            if (v.isValueOn()) {
                acc.setValueOn(v.getCoord(), *v);
            } else if (*v != background) {
                acc.setValueOff(v.getCoord(), *v);
            }
        }
    }
    for (auto it = from.tree().cbeginValueOn(); it; ++it) {
        if (!it.isVoxelValue()) into.tree().fill(it.getBoundingBox(), *it, true);
    }
}

}  // namespace

std::string EncodeKept(const WallsKept& k, const std::string& released) {
    std::string out;
    core::Put(out, k.occupied_columns);
    core::Put(out, k.voting_columns);
    core::Put(out, k.occupied.min());
    core::Put(out, k.occupied.max());
    core::PutVector(out, k.ground.entries());
    core::PutVector(out, k.voting_empty);
    core::PutVector(out, k.candidates);
    core::PutBytes(out, released);
    openvdb::GridPtrVec grids = k.map.Grids();
    k.observed_free->setName(kObservedFreeGrid);
    grids.push_back(k.observed_free);
    std::ostringstream os(std::ios_base::binary);
    openvdb::io::Stream(os).write(grids);
    return out + os.str();
}

std::string MergeKept(const std::string& bytes, WallsKept& into) {
    core::ByteReader in(bytes, "walls");
    into.occupied_columns += in.Get<size_t>();
    into.voting_columns += in.Get<size_t>();
    const Coord lo = in.Get<Coord>(), hi = in.Get<Coord>();
    if (!CoordBBox(lo, hi).empty()) {
        into.occupied.expand(lo);
        into.occupied.expand(hi);
    }
    for (const auto& e : in.GetVector<walls::GroundSample::Entry>()) into.ground.Add(e);
    for (const auto& e : in.GetVector<Coord>()) {
        into.voting_empty.push_back(e);
    }
    for (const Coord& c : in.GetVector<Coord>()) into.candidates.push_back(c);
    std::string released = in.GetBytes();
    std::istringstream is(in.Rest(), std::ios_base::binary);
    openvdb::io::Stream stream(is, /*delayLoad=*/false);
    openvdb::GridPtrVec grids = *stream.getGrids();
    const auto it = std::find_if(grids.begin(), grids.end(),
                                 [](const auto& g) { return g->getName() == kObservedFreeGrid; });
    const auto observed_free =
        it == grids.end() ? nullptr : openvdb::gridPtrCast<openvdb::BoolGrid>(*it);
    if (!observed_free) {
        throw FormatError(std::string("walls: a rank's answer has no ") + kObservedFreeGrid);
    }
    MergeVoxels(*observed_free, *into.observed_free);
    grids.erase(it);
    const core::VoxelMap map = core::VoxelMap::FromGrids(grids);
    MergeVoxels(*map.label, *into.map.label);
    MergeVoxels(*map.endpoints, *into.map.endpoints);
    return released;
}

}  // namespace strata::pipeline::detail
