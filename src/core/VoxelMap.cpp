#include "strata/core/VoxelMap.hpp"

#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <stdexcept>

#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"

namespace strata::core {
namespace {

constexpr const char* kProducer = "strata 0.1.0";

template <typename GridT>
typename GridT::Ptr MakeGrid(const char* name, const openvdb::math::Transform::Ptr& xform,
                             const char* units, openvdb::GridClass grid_class) {
    auto grid = GridT::create(typename GridT::ValueType(0));
    grid->setName(name);
    grid->setTransform(xform);
    grid->setGridClass(grid_class);
    grid->insertMeta("units", openvdb::StringMetadata(units));
    return grid;
}

template <typename GridT>
typename GridT::Ptr FindGrid(const openvdb::GridPtrVec& grids, const char* name) {
    for (const auto& g : grids) {
        if (g && g->getName() == name) {
            auto typed = openvdb::gridPtrCast<GridT>(g);
            if (!typed) {
                throw FormatError(std::string("grid '") + name + "' has type " + g->type() +
                                  ", expected " + GridT::gridType());
            }
            return typed;
        }
    }
    throw FormatError(std::string("the map has no '") + name + "' grid");
}

bool HasGrid(const openvdb::GridPtrVec& grids, const char* name) {
    return std::any_of(grids.begin(), grids.end(),
                       [&](const auto& g) { return g && g->getName() == name; });
}

void Stamp(openvdb::GridBase& grid, const Eigen::Vector3d& origin) {
    grid.insertMeta("producer", openvdb::StringMetadata(kProducer));
    grid.insertMeta("origin",
                    openvdb::Vec3DMetadata(openvdb::Vec3d(origin.x(), origin.y(), origin.z())));
}

openvdb::Int32Grid::Ptr MakeEndpointGrid(const openvdb::math::Transform::Ptr& xform) {
    auto grid = MakeGrid<openvdb::Int32Grid>(grid_names::kEndpoints, xform, "packed",
                                             openvdb::GRID_UNKNOWN);
    grid->insertMeta("encoding",
                     openvdb::StringMetadata(
                         "bits 0-10: hit count (saturating at 2047); bits 11-17, 18-24, 25-31: "
                         "mean endpoint offset from the voxel centre along x, y, z, in steps of "
                         "voxel/127, 63 = centre; strata export --format vdb writes them expanded "
                         "as 'hits' and 'point_mean'"));
    return grid;
}

// `hits` (and `point_mean`, when the map has it) of a map written before `endpoints` existed,
// packed; a voxel without a mean gets its centre.
template <typename RequireAligned>
openvdb::Int32Grid::Ptr PackOldEndpoints(const openvdb::GridPtrVec& grids, double voxel_size,
                                         const RequireAligned& require_aligned) {
    const auto hits = FindGrid<openvdb::Int32Grid>(grids, grid_names::kHits);
    require_aligned(*hits);
    openvdb::Vec3SGrid::Ptr means;
    if (HasGrid(grids, grid_names::kPointMean)) {
        means = FindGrid<openvdb::Vec3SGrid>(grids, grid_names::kPointMean);
        require_aligned(*means);
    }
    auto packed = MakeEndpointGrid(hits->transform().copy());
    auto out = packed->getAccessor();
    for (auto it = hits->cbeginValueOn(); it; ++it) {
        openvdb::CoordBBox box;
        it.getBoundingBox(box);
        for (const openvdb::Coord& ijk : box) {
            openvdb::Vec3s m(0.0f);
            if (means) means->tree().probeValue(ijk, m);
            out.setValueOn(ijk, endpoint::Pack(*it, Eigen::Vector3d(m[0], m[1], m[2]), voxel_size));
        }
    }
    return packed;
}

}  // namespace

openvdb::math::Transform::Ptr VoxelMap::MakeTransform(double voxel_size_m) {
    // Index (i, j, k) sits at the centre of [i*s, (i+1)*s): OctoMap's key convention.
    auto xform = openvdb::math::Transform::createLinearTransform(voxel_size_m);
    xform->postTranslate(openvdb::Vec3d(0.5 * voxel_size_m));
    return xform;
}

VoxelMap VoxelMap::Create(double voxel_size_m, const Eigen::Vector3d& origin) {
    if (!(voxel_size_m > 0.0) || !std::isfinite(voxel_size_m)) {
        throw InvalidArgumentError("voxel size must be positive, got " +
                                   std::to_string(voxel_size_m));
    }
    if (!origin.allFinite()) throw InvalidArgumentError("map origin must be finite");
    openvdb::initialize();
    VoxelMap map;
    map.voxel_size = voxel_size_m;
    map.origin = origin;
    const auto xform = MakeTransform(voxel_size_m);
    map.occupancy = MakeGrid<openvdb::FloatGrid>(grid_names::kOccupancy, xform, "log-odds",
                                                 openvdb::GRID_UNKNOWN);
    map.label =
        MakeGrid<openvdb::Int32Grid>(grid_names::kLabel, xform, "class id", openvdb::GRID_UNKNOWN);
    map.label_weight = MakeGrid<openvdb::FloatGrid>(grid_names::kLabelWeight, xform, "votes",
                                                    openvdb::GRID_UNKNOWN);
    map.endpoints = MakeEndpointGrid(xform);
    map.label->insertMeta("class_legend", openvdb::StringMetadata(LegendJson()));
    return map;
}

VoxelMap VoxelMap::DeepCopy() const {
    VoxelMap copy = *this;
    copy.occupancy = occupancy ? occupancy->deepCopy() : nullptr;
    copy.label = label ? label->deepCopy() : nullptr;
    copy.label_weight = label_weight ? label_weight->deepCopy() : nullptr;
    copy.endpoints = endpoints ? endpoints->deepCopy() : nullptr;
    return copy;
}

openvdb::GridPtrVec VoxelMap::Grids() const {
    openvdb::GridPtrVec grids{occupancy, label, label_weight, endpoints};
    for (auto& g : grids) Stamp(*g, origin);
    return grids;
}

openvdb::GridPtrVec VoxelMap::ExportGrids() const {
    openvdb::GridPtrVec grids = Grids();
    grids.pop_back();  // endpoints, expanded instead
    auto hits = MakeGrid<openvdb::Int32Grid>(grid_names::kHits, occupancy->transform().copy(),
                                             "points", openvdb::GRID_UNKNOWN);
    auto means = MakeGrid<openvdb::Vec3SGrid>(grid_names::kPointMean, occupancy->transform().copy(),
                                              "m from the voxel centre", openvdb::GRID_UNKNOWN);
    hits->tree().topologyUnion(endpoints->tree());
    means->tree().topologyUnion(endpoints->tree());
    openvdb::tree::LeafManager<openvdb::Int32Tree> leaves(hits->tree());
    leaves.foreach ([&](openvdb::Int32Tree::LeafNodeType& leaf, size_t) {
        const auto* packed = endpoints->tree().probeConstLeaf(leaf.origin());
        auto* mean = means->tree().probeLeaf(leaf.origin());
        for (auto on = leaf.beginValueOn(); on; ++on) {
            const int32_t value = packed->getValue(on.pos());
            on.setValue(endpoint::Hits(value));
            const Eigen::Vector3f offset = endpoint::Offset(value, voxel_size).cast<float>();
            mean->setValueOnly(on.pos(), openvdb::Vec3s(offset.x(), offset.y(), offset.z()));
        }
    });
    for (const auto& g : {openvdb::GridBase::Ptr(hits), openvdb::GridBase::Ptr(means)}) {
        Stamp(*g, origin);
        grids.push_back(g);
    }
    return grids;
}

VoxelMap VoxelMap::FromGrids(const openvdb::GridPtrVec& grids) {
    VoxelMap map;
    map.occupancy = FindGrid<openvdb::FloatGrid>(grids, grid_names::kOccupancy);
    map.label = FindGrid<openvdb::Int32Grid>(grids, grid_names::kLabel);
    map.label_weight = FindGrid<openvdb::FloatGrid>(grids, grid_names::kLabelWeight);
    const openvdb::Vec3d vs = map.occupancy->voxelSize();
    if (!(vs[0] > 0.0) || vs[0] != vs[1] || vs[0] != vs[2]) {
        throw FormatError("the occupancy grid does not have cubic voxels");
    }
    map.voxel_size = vs[0];
    const auto expected = MakeTransform(map.voxel_size);
    const auto require_aligned = [&](const openvdb::GridBase& g) {
        if (g.transform() != *expected) {
            throw FormatError("grid '" + g.getName() + "' is not aligned with 'occupancy'");
        }
    };
    for (const auto& g :
         {openvdb::GridBase::Ptr(map.label), openvdb::GridBase::Ptr(map.label_weight)}) {
        require_aligned(*g);
    }
    if (HasGrid(grids, grid_names::kEndpoints)) {
        map.endpoints = FindGrid<openvdb::Int32Grid>(grids, grid_names::kEndpoints);
        require_aligned(*map.endpoints);
    } else {  // written before endpoints were packed: `hits`, and `point_mean` if at all
        map.endpoints = PackOldEndpoints(grids, map.voxel_size, require_aligned);
    }
    if (const auto meta = map.occupancy->getMetadata<openvdb::Vec3DMetadata>("origin")) {
        const openvdb::Vec3d o = meta->value();
        map.origin = Eigen::Vector3d(o[0], o[1], o[2]);
    }
    return map;
}

bool VoxelMap::IsMapGrid(const std::string& name) {
    for (const char* own : {grid_names::kOccupancy, grid_names::kLabel, grid_names::kLabelWeight,
                            grid_names::kEndpoints, grid_names::kHits, grid_names::kPointMean}) {
        if (name == own) return true;
    }
    return false;
}

openvdb::Coord VoxelMap::WorldToVoxel(const Eigen::Vector3d& p_map) const {
    const double inv = 1.0 / voxel_size;
    return {static_cast<int32_t>(std::floor(p_map.x() * inv)),
            static_cast<int32_t>(std::floor(p_map.y() * inv)),
            static_cast<int32_t>(std::floor(p_map.z() * inv))};
}

Eigen::Vector3d VoxelMap::VoxelCenter(const openvdb::Coord& ijk) const {
    return (Eigen::Vector3d(ijk.x(), ijk.y(), ijk.z()) + Eigen::Vector3d::Constant(0.5)) *
           voxel_size;
}

int32_t VoxelMap::Hits(const openvdb::Coord& ijk) const {
    return endpoint::Hits(endpoints->tree().getValue(ijk));
}

Eigen::Vector3d VoxelMap::PointMean(const openvdb::Coord& ijk) const {
    int32_t packed = 0;
    return endpoints->tree().probeValue(ijk, packed)
               ? VoxelCenter(ijk) + endpoint::Offset(packed, voxel_size)
               : VoxelCenter(ijk);
}

void VoxelMap::SetEndpoints(const openvdb::Coord& ijk, int64_t hits,
                            const Eigen::Vector3d& offset_m) {
    endpoints->tree().setValueOn(ijk, endpoint::Pack(hits, offset_m, voxel_size));
}

}  // namespace strata::core
