#pragma once

#include <openvdb/Types.h>  // openvdb::Coord, without the grid types

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace strata::geometry {

/// Label of a point DBSCAN left unclustered.
inline constexpr int kNoise = -1;

/// @brief DBSCAN (Ester et al. 1996) on voxels, with the voxel grid itself as the neighbour
/// index: the neighbours of a voxel are the voxels of the set within `eps_voxels` (Euclidean,
/// in voxel units). A voxel with at least `min_points` neighbours (itself included) is a core
/// voxel; clusters are core voxels linked through each other plus the border voxels they reach.
/// @return one label per voxel: 0, 1, ... in order of first appearance, or kNoise.
/// @throw InvalidArgumentError unless eps_voxels >= 1 and min_points >= 1.
[[nodiscard]] std::vector<int> Dbscan(const std::vector<openvdb::Coord>& voxels, double eps_voxels,
                                      int min_points);

/// @brief The voxels in groups that DBSCAN with this `eps_voxels` can never join: two voxels
/// within `eps_voxels` of each other are in one group. DBSCAN of a group on its own gives that
/// group the clusters and noise DBSCAN of all the voxels gives it when both take the voxels in
/// Coord's order (up to the clusters' numbers).
/// @return the groups, each sorted (Coord's order, duplicates dropped), in order of their first
/// voxel.
/// @throw InvalidArgumentError unless eps_voxels >= 1.
[[nodiscard]] std::vector<std::vector<openvdb::Coord>> ConnectedVoxels(
    std::vector<openvdb::Coord> voxels, double eps_voxels);

/// @brief Lloyd's K-means with k-means++ seeding (deterministic for a seed). k is clamped to
/// [1, points.size()].
/// @return one cluster index in [0, k) per point; empty for no points.
[[nodiscard]] std::vector<int> KMeans(const std::vector<Eigen::Vector3d>& points, int k,
                                      uint64_t seed = 1, int max_iterations = 15);

}  // namespace strata::geometry
