#pragma once
// The pieces walls are made of (private to the walls module): the accepted parts before merging
// and the measurements the merge and the wall tests take of them.
#include <Eigen/Core>
#include <numeric>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/core/Labels.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/geometry/PlaneFit.hpp"

namespace strata::walls::detail {

// A K-means part: its cluster's first voxel and its number in the cluster, which name it
// whatever else the map holds.
struct PartKey {
    openvdb::Coord cluster;
    int part = 0;
    friend bool operator<(const PartKey& a, const PartKey& b) {
        return a.cluster != b.cluster ? a.cluster < b.cluster : a.part < b.part;
    }
};

// An accepted part, before merging.
struct Piece {
    geometry::Plane plane;
    Eigen::Vector3d centroid;
    Eigen::Vector3d lo, hi;               // box of the inliers
    std::vector<openvdb::Coord> voxels;   // every voxel of the part
    std::vector<Eigen::Vector3d> points;  // their endpoint means
    size_t inliers = 0;                   // points within the threshold of `plane`
};

// How many of b's points a's plane holds, relative to b's own plane.
[[nodiscard]] double Support(const Piece& a, const Piece& b, double threshold);

// Distance between the inlier boxes of two pieces (0 when they touch or overlap).
[[nodiscard]] double BoxGap(const Piece& a, const Piece& b);

struct UnionFind {
    std::vector<int> parent;
    explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
    int Find(int a) {
        while (parent[a] != a) a = parent[a] = parent[parent[a]];
        return a;
    }
    void Join(int a, int b) { parent[Find(a)] = Find(b); }
};

// Orients a wall normal towards the side the scanner saw: of the voxels two voxels in front of
// and behind a sample of inliers, the side with more observed-free voxels is the front. A voxel
// is observed free where `observed_free` is on, or without it, where the occupancy is <= 0.
[[nodiscard]] Eigen::Vector3d TowardsObservedSide(const core::VoxelMap& map,
                                                  const openvdb::BoolGrid* observed_free,
                                                  const std::vector<openvdb::Coord>& voxels,
                                                  const Eigen::Vector3d& normal);

// Extent of points along the horizontal direction of a plane with this normal.
[[nodiscard]] double HorizontalExtent(const std::vector<Eigen::Vector3d>& points,
                                      const Eigen::Vector3d& normal);

// One-sigma of the mean of `values` from their median absolute deviation (0 for fewer than 3).
[[nodiscard]] double SpreadOfMean(std::vector<double> values);

// The most frequent class among the voxels (kUnknown for a map without labels).
[[nodiscard]] core::SemanticClass DominantClass(const core::VoxelMap& map,
                                                const std::vector<openvdb::Coord>& voxels);

}  // namespace strata::walls::detail
