#include "strata/core/VoxelMap.hpp"

#include <algorithm>
#include <stdexcept>

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
                throw std::runtime_error(std::string("grid '") + name + "' has type " + g->type() +
                                         ", expected " + GridT::gridType());
            }
            return typed;
        }
    }
    throw std::runtime_error(std::string("the map has no '") + name + "' grid");
}

bool HasGrid(const openvdb::GridPtrVec& grids, const char* name) {
    return std::any_of(grids.begin(), grids.end(),
                       [&](const auto& g) { return g && g->getName() == name; });
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
        throw std::invalid_argument("voxel size must be positive, got " +
                                    std::to_string(voxel_size_m));
    }
    if (!origin.allFinite()) throw std::invalid_argument("map origin must be finite");
    openvdb::initialize();
    VoxelMap map;
    map.voxel_size = voxel_size_m;
    map.origin = origin;
    const auto xform = MakeTransform(voxel_size_m);
    map.occupancy = MakeGrid<openvdb::FloatGrid>(grid_names::kOccupancy, xform, "log-odds",
                                                 openvdb::GRID_UNKNOWN);
    map.label = MakeGrid<openvdb::Int32Grid>(grid_names::kLabel, xform, "class id",
                                             openvdb::GRID_UNKNOWN);
    map.label_weight = MakeGrid<openvdb::FloatGrid>(grid_names::kLabelWeight, xform, "votes",
                                                    openvdb::GRID_UNKNOWN);
    map.hits = MakeGrid<openvdb::Int32Grid>(grid_names::kHits, xform, "points",
                                            openvdb::GRID_UNKNOWN);
    map.point_mean = MakeGrid<openvdb::Vec3SGrid>(grid_names::kPointMean, xform,
                                                  "m from the voxel centre", openvdb::GRID_UNKNOWN);
    map.label->insertMeta("class_legend", openvdb::StringMetadata(LegendJson()));
    return map;
}

VoxelMap VoxelMap::DeepCopy() const {
    VoxelMap copy = *this;
    copy.occupancy = occupancy ? occupancy->deepCopy() : nullptr;
    copy.label = label ? label->deepCopy() : nullptr;
    copy.label_weight = label_weight ? label_weight->deepCopy() : nullptr;
    copy.hits = hits ? hits->deepCopy() : nullptr;
    copy.point_mean = point_mean ? point_mean->deepCopy() : nullptr;
    return copy;
}

openvdb::GridPtrVec VoxelMap::Grids() const {
    openvdb::GridPtrVec grids{occupancy, label, label_weight, hits, point_mean};
    for (auto& g : grids) {
        g->insertMeta("producer", openvdb::StringMetadata(kProducer));
        g->insertMeta("origin", openvdb::Vec3DMetadata(openvdb::Vec3d(origin.x(), origin.y(),
                                                                      origin.z())));
    }
    return grids;
}

VoxelMap VoxelMap::FromGrids(const openvdb::GridPtrVec& grids) {
    VoxelMap map;
    map.occupancy = FindGrid<openvdb::FloatGrid>(grids, grid_names::kOccupancy);
    map.label = FindGrid<openvdb::Int32Grid>(grids, grid_names::kLabel);
    map.label_weight = FindGrid<openvdb::FloatGrid>(grids, grid_names::kLabelWeight);
    map.hits = FindGrid<openvdb::Int32Grid>(grids, grid_names::kHits);
    if (HasGrid(grids, grid_names::kPointMean)) {
        map.point_mean = FindGrid<openvdb::Vec3SGrid>(grids, grid_names::kPointMean);
    } else {  // written before the grid existed
        map.point_mean = MakeGrid<openvdb::Vec3SGrid>(grid_names::kPointMean,
                                                      map.occupancy->transform().copy(),
                                                      "m from the voxel centre",
                                                      openvdb::GRID_UNKNOWN);
    }
    const openvdb::Vec3d vs = map.occupancy->voxelSize();
    if (!(vs[0] > 0.0) || vs[0] != vs[1] || vs[0] != vs[2]) {
        throw std::runtime_error("the occupancy grid does not have cubic voxels");
    }
    map.voxel_size = vs[0];
    const auto expected = MakeTransform(map.voxel_size);
    for (const auto& g : {openvdb::GridBase::Ptr(map.label), openvdb::GridBase::Ptr(map.label_weight),
                          openvdb::GridBase::Ptr(map.hits), openvdb::GridBase::Ptr(map.point_mean)}) {
        if (g->transform() != *expected) {
            throw std::runtime_error("grid '" + g->getName() + "' is not aligned with 'occupancy'");
        }
    }
    if (const auto meta = map.occupancy->getMetadata<openvdb::Vec3DMetadata>("origin")) {
        const openvdb::Vec3d o = meta->value();
        map.origin = Eigen::Vector3d(o[0], o[1], o[2]);
    }
    return map;
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

Eigen::Vector3d VoxelMap::PointMean(const openvdb::Coord& ijk) const {
    Eigen::Vector3d p = VoxelCenter(ijk);
    openvdb::Vec3s offset;
    if (point_mean && point_mean->tree().probeValue(ijk, offset)) {
        p += Eigen::Vector3d(offset[0], offset[1], offset[2]);
    }
    return p;
}

}  // namespace strata::core
