#include "strata/io/OctomapExport.hpp"

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <openvdb/tools/Count.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "ExportInput.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/io/AtomicFile.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::io {
namespace {

// OctoMap's default clamping, [0.12, 0.97] in probability; widened only when the map needs it.
constexpr double kDefaultClampMinLogOdds = -2.0;
constexpr double kDefaultClampMaxLogOdds = 3.5;

void CheckExtent(const core::VoxelMap& map, const std::filesystem::path& path) {
    const openvdb::CoordBBox bbox = map.occupancy->evalActiveVoxelBoundingBox();
    if (bbox.empty()) return;
    const openvdb::Coord lo = bbox.min();
    const openvdb::Coord hi = bbox.max();
    bool fits = true;
    for (int axis = 0; axis < 3; ++axis) {
        fits = fits && lo[axis] >= -kOctomapKeyLimit && hi[axis] < kOctomapKeyLimit;
    }
    if (fits) return;
    const double s = map.voxel_size;
    std::ostringstream msg;
    msg << "cannot write '" << path.string() << "' as OctoMap: the map spans voxels " << lo
        << " to " << hi << " (x " << lo.x() * s << ".." << (hi.x() + 1) * s << " m, y "
        << lo.y() * s << ".." << (hi.y() + 1) * s << " m, z " << lo.z() * s << ".."
        << (hi.z() + 1) * s << " m), but OctoMap's 16-bit keys hold only voxels "
        << -kOctomapKeyLimit << ".." << kOctomapKeyLimit - 1 << " per axis (+-"
        << kOctomapKeyLimit * s << " m at " << s << " m voxels); crop or tile the map first";
    throw RefusedError(msg.str());
}

octomap::OcTreeKey KeyOf(const openvdb::Coord& ijk) {
    return {static_cast<octomap::key_type>(ijk.x() + kOctomapKeyLimit),
            static_cast<octomap::key_type>(ijk.y() + kOctomapKeyLimit),
            static_cast<octomap::key_type>(ijk.z() + kOctomapKeyLimit)};
}

// Copies every observed voxel into `tree` (lazily: inner nodes are updated once at the end).
// `on_node(node, ijk, log_odds)` may decorate the leaf just written.
template <typename TreeT, typename OnNode>
void CopyOccupancy(const core::VoxelMap& map, TreeT& tree, OnNode&& on_node) {
    const auto range = openvdb::tools::minMax(map.occupancy->tree());
    // Widen clamping a little past the map's extremes so that setNodeValue keeps values as they
    // are.
    if (range.min() < kDefaultClampMinLogOdds) {
        tree.setClampingThresMin(core::Probability(range.min() - 0.01f));
    }
    if (range.max() > kDefaultClampMaxLogOdds) {
        tree.setClampingThresMax(core::Probability(range.max() + 0.01f));
    }
    const float below_zero = std::nextafter(0.0f, -1.0f);
    detail::ForEachObservedVoxel(*map.occupancy, [&](const openvdb::Coord& ijk, float log_odds) {
        auto* node = tree.setNodeValue(KeyOf(ijk), log_odds == 0.0f ? below_zero : log_odds,
                                       /*lazy_eval=*/true);
        on_node(node, ijk, log_odds);
    });
    tree.updateInnerOccupancy();
}

void WriteBinaryTree(const core::VoxelMap& map, const std::filesystem::path& path) {
    octomap::OcTree tree(map.voxel_size);
    CopyOccupancy(map, tree, [](octomap::OcTreeNode*, const openvdb::Coord&, float) {});
    WriteFileAtomically(path, [&](std::ostream& os) {
        if (!tree.writeBinary(os)) throw IoError("OctoMap could not serialise the tree");
    });
}

void WriteColorTree(const core::VoxelMap& map, const std::filesystem::path& path) {
    octomap::ColorOcTree tree(map.voxel_size);
    openvdb::Int32Grid::ConstAccessor labels = map.label->getConstAccessor();
    CopyOccupancy(map, tree,
                  [&](octomap::ColorOcTreeNode* node, const openvdb::Coord& ijk, float log_odds) {
                      if (!(log_odds > 0.0f)) return;
                      const core::Rgb c = core::ClassColor(detail::ClassOf(labels.getValue(ijk)));
                      node->setColor(c.r, c.g, c.b);
                  });
    // AbstractOcTree::write keeps every leaf: no pruning, so no colour averaging.
    WriteFileAtomically(path, [&](std::ostream& os) {
        if (!tree.write(os)) throw IoError("OctoMap could not serialise the tree");
    });
}

}  // namespace

void WriteOctomap(const core::VoxelMap& map, const std::filesystem::path& path) {
    detail::RequireGrids(map, path);
    const std::string ext = LowerExtension(path);
    if (ext != ".bt" && ext != ".ot") {
        throw InvalidArgumentError("cannot write '" + path.string() +
                                   "' as OctoMap: the extension must be .bt or .ot");
    }
    CheckExtent(map, path);
    if (ext == ".bt") {
        WriteBinaryTree(map, path);
    } else {
        WriteColorTree(map, path);
    }
}

}  // namespace strata::io
