#include "Pieces.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace strata::walls::detail {

// How many of b's points a's plane holds, relative to b's own plane.
double Support(const Piece& a, const Piece& b, double threshold) {
    size_t on = 0;
    for (const auto& p : b.points) on += std::abs(a.plane.Distance(p)) <= threshold;
    return b.inliers ? static_cast<double>(on) / static_cast<double>(b.inliers) : 0.0;
}

double BoxGap(const Piece& a, const Piece& b) {
    const Eigen::Vector3d gap =
        (a.lo - b.hi).cwiseMax(b.lo - a.hi).cwiseMax(Eigen::Vector3d::Zero());
    return gap.norm();
}

// Orients a wall normal towards the side the scanner saw: of the voxels two voxels in front of
// and behind a sample of inliers, the side with more observed-free voxels is the front.
Eigen::Vector3d TowardsObservedSide(const core::VoxelMap& map,
                                    const openvdb::BoolGrid* observed_free,
                                    const std::vector<openvdb::Coord>& voxels,
                                    const Eigen::Vector3d& normal) {
    auto occupancy = map.occupancy->getConstAccessor();
    const openvdb::BoolGrid::Ptr none = observed_free ? nullptr : openvdb::BoolGrid::create(false);
    auto seen_free = (observed_free ? *observed_free : *none).getConstAccessor();
    const size_t step = std::max<size_t>(1, voxels.size() / 256);
    int front = 0, back = 0;
    auto free_at = [&](const Eigen::Vector3d& p) {
        const openvdb::Coord c = map.WorldToVoxel(p);
        if (observed_free) return seen_free.isValueOn(c);
        float value = 0.0f;
        return occupancy.probeValue(c, value) && value <= 0.0f;
    };
    for (size_t n = 0; n < voxels.size(); n += step) {
        const Eigen::Vector3d p = map.PointMean(voxels[n]);
        front += free_at(p + 2.0 * map.voxel_size * normal);
        back += free_at(p - 2.0 * map.voxel_size * normal);
    }
    return back > front ? Eigen::Vector3d(-normal) : normal;
}

// Extent of points along the horizontal direction of a plane with this normal.
double HorizontalExtent(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& normal) {
    const Eigen::Vector3d along = Eigen::Vector3d::UnitZ().cross(normal);
    if (points.empty() || along.norm() < 1e-9) return 0.0;
    double lo = 1e300, hi = -1e300;
    for (const auto& p : points) {
        lo = std::min(lo, p.dot(along.normalized()));
        hi = std::max(hi, p.dot(along.normalized()));
    }
    return hi - lo;
}

// One-sigma of the mean of `values` from their median absolute deviation (0 for fewer than 3).
double SpreadOfMean(std::vector<double> values) {
    if (values.size() < 3) return 0.0;
    const auto median = [](std::vector<double>& v) {
        std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
        return v[v.size() / 2];
    };
    const double m = median(values);
    for (double& v : values) v = std::abs(v - m);
    constexpr double kMadToSigma = 1.4826;
    return kMadToSigma * median(values) / std::sqrt(static_cast<double>(values.size()));
}

core::SemanticClass DominantClass(const core::VoxelMap& map,
                                  const std::vector<openvdb::Coord>& voxels) {
    if (!map.label) return core::SemanticClass::kUnknown;
    std::array<size_t, core::kNumClasses> counts{};
    auto label = map.label->getConstAccessor();
    for (const auto& c : voxels) {
        const int l = label.getValue(c);
        if (l >= 0 && l < core::kNumClasses) ++counts[static_cast<size_t>(l)];
    }
    const auto best = std::max_element(counts.begin(), counts.end());
    return static_cast<core::SemanticClass>(best - counts.begin());
}

}  // namespace strata::walls::detail
