#include <gtest/gtest.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <memory>

#include "ExportTestMap.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/OctomapExport.hpp"

namespace strata::io {
namespace {

using namespace export_test;

struct Counts {
    uint64_t occupied = 0;
    uint64_t free = 0;
};

// Our occupied/free voxel counts (tiles expanded; log-odds 0 counts as free).
Counts CountMap(const core::VoxelMap& map) {
    Counts c;
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        (*it > 0.0f ? c.occupied : c.free) += it.getVoxelCount();
    }
    return c;
}

// OctoMap's occupied/free voxel counts at full resolution (pruned leaves expanded).
template <typename TreeT>
Counts CountTree(const TreeT& tree) {
    Counts c;
    for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
        const uint64_t n = uint64_t{1} << (3 * (tree.getTreeDepth() - it.getDepth()));
        (tree.isNodeOccupied(*it) ? c.occupied : c.free) += n;
    }
    return c;
}

// Every observed voxel of ours has the same state at its centre in the tree.
template <typename TreeT, typename Check>
void ForEachVoxelNode(const core::VoxelMap& map, const TreeT& tree, Check&& check) {
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        openvdb::CoordBBox bbox;
        it.getBoundingBox(bbox);
        for (auto ijk = bbox.begin(); ijk; ++ijk) {
            const Eigen::Vector3d p = map.VoxelCenter(*ijk);
            const auto* node = tree.search(p.x(), p.y(), p.z());
            ASSERT_NE(node, nullptr) << *ijk;
            ASSERT_EQ(tree.isNodeOccupied(node), *it > 0.0f) << *ijk;
            check(*ijk, *it, *node);
        }
    }
}

TEST(OctomapExport, BinaryTreeHasTheSameOccupiedAndFreeVoxels) {
    const ScratchDir dir("octomap_bt");
    const core::VoxelMap map = MakeExportTestMap();
    WriteOctomap(map, dir / "map.bt");
    EXPECT_EQ(dir.EntryCount(), 1);
    octomap::OcTree tree((dir / "map.bt").string());
    EXPECT_DOUBLE_EQ(tree.getResolution(), kVoxelSize);
    ForEachVoxelNode(map, tree, [](const openvdb::Coord&, float, const octomap::OcTreeNode&) {});
    const Counts ours = CountMap(map);
    const Counts theirs = CountTree(tree);
    EXPECT_EQ(theirs.occupied, ours.occupied);
    EXPECT_EQ(theirs.free, ours.free);
    // Unknown stays unknown.
    const Eigen::Vector3d hole = map.VoxelCenter(kHole);
    EXPECT_EQ(tree.search(hole.x(), hole.y(), hole.z()), nullptr);
}

TEST(OctomapExport, ColorTreeKeepsLogOddsAndClassColours) {
    const ScratchDir dir("octomap_ot");
    const core::VoxelMap map = MakeExportTestMap();
    WriteOctomap(map, dir / "map.ot");
    std::unique_ptr<octomap::AbstractOcTree> read(
        octomap::AbstractOcTree::read((dir / "map.ot").string()));
    auto* tree = dynamic_cast<octomap::ColorOcTree*>(read.get());
    ASSERT_NE(tree, nullptr);
    EXPECT_DOUBLE_EQ(tree->getResolution(), kVoxelSize);
    auto labels = map.label->getConstAccessor();
    ForEachVoxelNode(
        map, *tree,
        [&](const openvdb::Coord& ijk, float log_odds, const octomap::ColorOcTreeNode& node) {
            if (log_odds == 0.0f) {
                EXPECT_LT(node.getLogOdds(), 0.0f);
                return;
            }
            EXPECT_EQ(node.getLogOdds(), log_odds) << ijk;
            if (log_odds > 0.0f) {
                const core::Rgb c =
                    core::ClassColor(static_cast<SemanticClass>(labels.getValue(ijk)));
                EXPECT_EQ(node.getColor(), octomap::ColorOcTreeNode::Color(c.r, c.g, c.b)) << ijk;
            }
        });
    // Not pruned: one leaf per observed voxel.
    EXPECT_EQ(tree->getNumLeafNodes(), map.occupancy->activeVoxelCount());
    const Counts ours = CountMap(map);
    const Counts theirs = CountTree(*tree);
    EXPECT_EQ(theirs.occupied, ours.occupied);
    EXPECT_EQ(theirs.free, ours.free);
}

TEST(OctomapExport, KeyRangeEdgesAreKept) {
    const ScratchDir dir("octomap_edges");
    core::VoxelMap map = core::VoxelMap::Create(kVoxelSize);
    const openvdb::Coord lo(-kOctomapKeyLimit, -kOctomapKeyLimit, -kOctomapKeyLimit);
    const openvdb::Coord hi(kOctomapKeyLimit - 1, kOctomapKeyLimit - 1, kOctomapKeyLimit - 1);
    map.occupancy->tree().setValueOn(lo, 1.0f);
    map.occupancy->tree().setValueOn(hi, -1.0f);
    WriteOctomap(map, dir / "edges.bt");
    octomap::OcTree tree((dir / "edges.bt").string());
    for (const openvdb::Coord& ijk : {lo, hi}) {
        const Eigen::Vector3d p = map.VoxelCenter(ijk);
        const auto* node = tree.search(p.x(), p.y(), p.z());
        ASSERT_NE(node, nullptr) << ijk;
        EXPECT_EQ(tree.isNodeOccupied(node), ijk == lo);
    }
}

TEST(OctomapExport, RefusesMapsBeyondTheKeyRange) {
    const ScratchDir dir("octomap_large");
    core::VoxelMap map = MakeExportTestMap();
    map.occupancy->tree().setValueOn({kOctomapKeyLimit, 0, 0}, 1.0f);  // 6553.6 m east
    try {
        WriteOctomap(map, dir / "map.bt");
        FAIL() << "expected std::runtime_error";
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("32767"), std::string::npos) << what;
        EXPECT_NE(what.find("6553.8"), std::string::npos) << what;  // the extent in metres
        EXPECT_NE(what.find("map.bt"), std::string::npos) << what;
    }
    EXPECT_EQ(dir.EntryCount(), 0);
}

TEST(OctomapExport, RejectsOtherExtensions) {
    const ScratchDir dir("octomap_ext");
    EXPECT_THROW(WriteOctomap(MakeExportTestMap(), dir / "map.vdb"), InvalidArgumentError);
    EXPECT_THROW(WriteOctomap(MakeExportTestMap(), dir / "map"), InvalidArgumentError);
    EXPECT_EQ(dir.EntryCount(), 0);
}

TEST(OctomapExport, MissingDirectoryThrowsNamingThePath) {
    const ScratchDir dir("octomap_missing");
    const fs::path path = dir / "missing/map.ot";
    ExpectErrorNaming(path, [&] { WriteOctomap(MakeExportTestMap(), path); });
    EXPECT_EQ(dir.EntryCount(), 0);
}

}  // namespace
}  // namespace strata::io
