#include "CellMerger.hpp"

#include <algorithm>
#include <cmath>

namespace strata::view::detail {

uint8_t ClassByte(int32_t label) {
    return label >= 0 && label < core::kNumClasses ? static_cast<uint8_t>(label) : 0;
}

namespace {

template <typename GridPtr>
auto ProbeLeaf(const GridPtr& grid, const openvdb::Coord& origin) {
    return grid ? grid->tree().probeConstLeaf(origin) : nullptr;
}

}  // namespace

VoxelAttributes::VoxelAttributes(const TileGrids& tile) : tile_(tile) {
    for (const auto& [id, layer] : tile.sessions) {
        if (layer) sessions_.emplace_back(id, nullptr);
    }
}

void VoxelAttributes::Leaf(const openvdb::Coord& origin) {
    label_ = ProbeLeaf(tile_.label, origin);
    size_t k = 0;
    for (const auto& [id, layer] : tile_.sessions) {
        if (layer) sessions_[k++].second = layer->tree().probeConstLeaf(origin);
    }
    slant_ = ProbeLeaf(tile_.slant_deg, origin);
    wall_id_ = ProbeLeaf(tile_.wall_id, origin);
    refilled_ = ProbeLeaf(tile_.refilled, origin);
}

Voxel VoxelAttributes::Of(openvdb::Index offset) const {
    Voxel v;
    if (label_) v.label = ClassByte(label_->getValue(offset));
    // The first session that saw the voxel occupied: when it appeared.
    for (const auto& [id, layer] : sessions_) {
        if (layer && layer->isValueOn(offset)) {
            v.session = static_cast<uint8_t>(std::clamp<int64_t>(id, 0, kNoValue - 1));
            break;
        }
    }
    if (slant_ && slant_->isValueOn(offset)) {
        v.slant_deg = slant_->getValue(offset);
        v.flags |= cell_flags::kWall;
        if (wall_id_ && wall_id_->isValueOn(offset)) {
            v.object = static_cast<uint16_t>(std::clamp(wall_id_->getValue(offset), 0, 65535));
        }
    }
    if (refilled_ && refilled_->isValueOn(offset)) v.flags |= cell_flags::kRefilled;
    return v;
}

CellMerger::CellMerger(int lod, Cells& out)
    : lod_(lod),
      cells_per_axis_(8 >> lod),
      out_(out),
      slot_(static_cast<size_t>(cells_per_axis_ * cells_per_axis_ * cells_per_axis_), -1) {}

void CellMerger::Add(const openvdb::Coord& ijk, const Voxel& voxel) {
    // Position of the cell inside its leaf (leaves are 8 voxels on a side, aligned to 8).
    const int n = cells_per_axis_;
    const size_t local = static_cast<size_t>(
        (((ijk.x() & 7) >> lod_) * n + ((ijk.y() & 7) >> lod_)) * n + ((ijk.z() & 7) >> lod_));
    if (slot_[local] < 0) {
        slot_[local] = static_cast<int>(open_.size());
        open_.emplace_back();
        open_.back().cell = ijk >> static_cast<size_t>(lod_);
        open_.back().local = local;
    }
    Accumulator& a = open_[static_cast<size_t>(slot_[local])];
    ++a.votes[voxel.label];
    a.session = std::min(a.session, voxel.session);
    if (voxel.slant_deg >= 0.0F) {
        a.slant_sum += voxel.slant_deg;
        ++a.slant_count;
    }
    a.flags |= voxel.flags;
    if (a.object == 0) a.object = voxel.object;
}

void CellMerger::Flush() {
    for (const Accumulator& a : open_) {
        out_.cell.push_back(a.cell);
        // Most frequent class; ties go to the lower class id, so the result is deterministic.
        out_.label.push_back(static_cast<uint8_t>(std::max_element(a.votes.begin(), a.votes.end()) -
                                                  a.votes.begin()));
        out_.session.push_back(a.session);
        const float half_degrees =
            std::round(2.0F * a.slant_sum / std::max<float>(1, a.slant_count));
        out_.slant.push_back(a.slant_count > 0
                                 ? static_cast<uint8_t>(std::clamp(half_degrees, 0.0F, 254.0F))
                                 : kNoValue);
        out_.flags.push_back(a.flags);
        out_.object.push_back(a.object);
        slot_[a.local] = -1;
    }
    open_.clear();
}

}  // namespace strata::view::detail
