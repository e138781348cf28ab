#include "strata/dynamic/Dynamic.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <string>

#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"

namespace strata::dynamic {
namespace {

// The offsets a candidate's neighbourhood spans (itself included).
std::vector<openvdb::Coord> Offsets(const DynamicConfig& config) {
    std::vector<openvdb::Coord> out;
    const int r = config.margin_voxels;
    for (int dx = -r; dx <= r; ++dx) {
        for (int dy = -r; dy <= r; ++dy) {
            for (int dz = -r; dz <= r; ++dz) {
                const int l1 = std::abs(dx) + std::abs(dy) + std::abs(dz);
                if (config.neighbourhood == Neighbourhood::kFaces && l1 > r) continue;
                out.emplace_back(dx, dy, dz);
            }
        }
    }
    return out;
}

// Groups of the removed voxels linked by steps of at most `gap` voxels along every axis, in
// order of their first voxel.
std::vector<std::vector<openvdb::Coord>> Groups(std::vector<openvdb::Coord> voxels, int gap) {
    std::sort(voxels.begin(), voxels.end());
    openvdb::MaskTree left;
    for (const openvdb::Coord& c : voxels) left.setValueOn(c);
    openvdb::tree::ValueAccessor<openvdb::MaskTree> acc(left);
    std::vector<std::vector<openvdb::Coord>> groups;
    for (const openvdb::Coord& seed : voxels) {
        if (!acc.isValueOn(seed)) continue;
        std::vector<openvdb::Coord> group{seed};
        acc.setValueOff(seed);
        for (size_t i = 0; i < group.size(); ++i) {
            const openvdb::Coord c = group[i];
            for (int dx = -gap; dx <= gap; ++dx) {
                for (int dy = -gap; dy <= gap; ++dy) {
                    for (int dz = -gap; dz <= gap; ++dz) {
                        const openvdb::Coord n = c.offsetBy(dx, dy, dz);
                        if (!acc.isValueOn(n)) continue;
                        acc.setValueOff(n);
                        group.push_back(n);
                    }
                }
            }
        }
        groups.push_back(std::move(group));
    }
    return groups;
}

// Calls `visit` with each active voxel of `tree` inside `region`, skipping the leaves outside it:
// a map stored tile by tile applies the result once per tile. The result's grids hold voxels
// only (GroupVerdicts sets them one by one), no active tiles.
template <typename TreeT, typename Visit>
void ForEachIn(const TreeT& tree, const openvdb::CoordBBox& region, Visit&& visit) {
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        if (!region.hasOverlap(leaf->getNodeBoundingBox())) continue;
        for (auto on = leaf->cbeginValueOn(); on; ++on) {
            if (region.isInside(on.getCoord())) visit(on.getCoord());
        }
    }
}

}  // namespace

void DynamicConfig::Validate() const {
    if (margin_voxels < 0 || margin_voxels > 4) {
        throw InvalidArgumentError("margin_voxels must be in [0, 4], not " +
                                   std::to_string(margin_voxels));
    }
    if (object_gap_voxels < 1 || object_gap_voxels > 8) {
        throw InvalidArgumentError("object_gap_voxels must be in [1, 8], not " +
                                   std::to_string(object_gap_voxels));
    }
    if (!(restored_log_odds > 0.0F)) {
        throw InvalidArgumentError("restored_log_odds must be > 0 (occupied)");
    }
    if (!(removed_log_odds <= 0.0F)) {
        throw InvalidArgumentError("removed_log_odds must be <= 0 (free)");
    }
}

size_t DynamicResult::restored_voxels() const {
    return restored ? static_cast<size_t>(restored->activeVoxelCount()) : 0;
}

void VoxelVerdicts::Append(VoxelVerdicts&& part) {
    const auto move = [](std::vector<openvdb::Coord>& to, std::vector<openvdb::Coord>& from) {
        to.insert(to.end(), from.begin(), from.end());
    };
    move(removed, part.removed);
    move(occupied, part.occupied);
    move(restored, part.restored);
    occupied_voxels += part.occupied_voxels;
}

VoxelVerdicts JudgeVoxels(const core::VoxelMap& map, const SeenSpace& seen,
                          const DynamicConfig& config) {
    config.Validate();
    if (!seen.crossed || !seen.hit) {
        throw InvalidArgumentError("the space the rays crossed and hit is needed");
    }
    const std::vector<openvdb::Coord> offsets = Offsets(config);
    std::vector<const openvdb::MaskTree::LeafNodeType*> leaves;
    seen.hit->tree().getNodes(leaves);
    std::vector<VoxelVerdicts> parts(leaves.size());
    const openvdb::FloatTree& occupancy = map.occupancy->tree();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size()), [&](const auto& range) {
        openvdb::tree::ValueAccessor<const openvdb::FloatTree> occ(occupancy);
        openvdb::tree::ValueAccessor<const openvdb::MaskTree> crossed(seen.crossed->tree());
        for (size_t i = range.begin(); i != range.end(); ++i) {
            for (auto on = leaves[i]->cbeginValueOn(); on; ++on) {
                const openvdb::Coord c = on.getCoord();
                float value = 0.0F;
                // Occupied now, or never observed (cleared by another analysis): not a candidate.
                if (!occ.probeValue(c, value) || (value > 0.0F && !config.occupied_too)) continue;
                const bool through =
                    std::all_of(offsets.begin(), offsets.end(),
                                [&](const auto& d) { return crossed.isValueOn(c + d); });
                if (through) {
                    parts[i].removed.push_back(c);
                    if (value > 0.0F) parts[i].occupied.push_back(c);
                } else if (value <= 0.0F) {
                    parts[i].restored.push_back(c);
                }
            }
        }
    });
    VoxelVerdicts out;
    for (VoxelVerdicts& part : parts) out.Append(std::move(part));
    for (auto on = occupancy.cbeginValueOn(); on; ++on) {
        if (*on > 0.0F) out.occupied_voxels += on.getVoxelCount();
    }
    return out;
}

DynamicResult GroupVerdicts(VoxelVerdicts verdicts, const openvdb::math::Transform& transform,
                            double voxel_size, const DynamicConfig& config) {
    config.Validate();
    DynamicResult result;
    result.removed = openvdb::Int32Grid::create(0);
    result.removed->setTransform(transform.copy());
    result.removed->setName(grid_names::kRemoved);
    result.restored = openvdb::BoolGrid::create(false);
    result.restored->setTransform(transform.copy());
    result.restored->setName(grid_names::kRestored);
    openvdb::MaskTree occupied;
    for (const openvdb::Coord& c : verdicts.occupied) occupied.setValueOn(c);
    for (const openvdb::Coord& c : verdicts.restored) result.restored->tree().setValueOn(c, true);
    result.candidates = verdicts.removed.size() + verdicts.restored.size();
    result.removed_occupied = verdicts.occupied.size();
    result.occupied = verdicts.occupied_voxels;
    for (std::vector<openvdb::Coord>& group :
         Groups(std::move(verdicts.removed), config.object_gap_voxels)) {
        int32_t id = 0;
        if (group.size() >= config.min_object_voxels) {
            MovingObject object;
            object.id = static_cast<int32_t>(result.objects.size() + 1);
            object.voxels = group.size();
            for (const openvdb::Coord& c : group) {
                object.box.extend(Eigen::Vector3d(c.x(), c.y(), c.z()) * voxel_size);
                object.box.extend(Eigen::Vector3d(c.x() + 1, c.y() + 1, c.z() + 1) * voxel_size);
            }
            id = object.id;
            result.objects.push_back(object);
        } else {
            result.scattered += group.size();
            if (config.keep_scattered) {
                for (const openvdb::Coord& c : group) {
                    if (occupied.isValueOn(c)) {
                        --result.removed_occupied;  // stays as it was
                    } else {
                        result.restored->tree().setValueOn(c, true);
                    }
                }
                continue;
            }
        }
        for (const openvdb::Coord& c : group) result.removed->tree().setValueOn(c, id);
    }
    result.static_voxels = result.occupied + result.restored_voxels() - result.removed_occupied;
    return result;
}

DynamicResult FindDynamic(const core::VoxelMap& map, const SeenSpace& seen,
                          const DynamicConfig& config) {
    return GroupVerdicts(JudgeVoxels(map, seen, config), map.occupancy->transform(), map.voxel_size,
                         config);
}

void ApplyDynamic(const DynamicResult& result, const DynamicConfig& config, core::VoxelMap& map,
                  const openvdb::CoordBBox& region) {
    config.Validate();
    auto& occupancy = map.occupancy->tree();
    ForEachIn(result.restored->tree(), region,
              [&](const openvdb::Coord& c) { occupancy.setValueOn(c, config.restored_log_odds); });
    const auto dynamic = static_cast<int32_t>(core::SemanticClass::kDynamic);
    ForEachIn(result.removed->tree(), region, [&](const openvdb::Coord& c) {
        if (occupancy.getValue(c) > 0.0F) occupancy.setValueOn(c, config.removed_log_odds);
        map.endpoints->tree().setValueOff(c, 0);
        map.label->tree().setValueOn(c, dynamic);
    });
}

}  // namespace strata::dynamic
