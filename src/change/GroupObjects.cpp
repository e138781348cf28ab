// Changed voxels -> objects: the voxels grouped within the gap tolerance (geometry::GroupVoxels),
// then per-object statistics.
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "strata/change/ChangeDetection.hpp"
#include "strata/geometry/Grouping.hpp"

namespace strata::change {
namespace {

using openvdb::Coord;

ChangeObject Describe(const std::vector<Coord>& voxels, ChangeKind kind, double s,
                      const openvdb::Int32Grid* labels) {
    ChangeObject o;
    o.kind = kind;
    o.voxels = voxels.size();
    o.volume_m3 = static_cast<double>(voxels.size()) * s * s * s;
    Coord lo = voxels.front(), hi = voxels.front();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const auto centre = [s](const Coord& c) {
        return Eigen::Vector3d((c.x() + 0.5) * s, (c.y() + 0.5) * s, (c.z() + 0.5) * s);
    };
    for (const Coord& c : voxels) {
        lo.minComponent(c);
        hi.maxComponent(c);
        sum += centre(c);
    }
    const double n = static_cast<double>(voxels.size());
    o.centroid = sum / n;
    o.bbox_min = Eigen::Vector3d(lo.x(), lo.y(), lo.z()) * s;
    o.bbox_max = Eigen::Vector3d(hi.x() + 1, hi.y() + 1, hi.z() + 1) * s;

    // Oriented box: principal axes of the x/y positions.
    double cxx = 0.0, cxy = 0.0, cyy = 0.0;
    for (const Coord& c : voxels) {
        const Eigen::Vector3d d = centre(c) - o.centroid;
        cxx += d.x() * d.x();
        cxy += d.x() * d.y();
        cyy += d.y() * d.y();
    }
    double yaw = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);
    if (yaw <= -M_PI / 2.0) yaw += M_PI;
    const Eigen::Vector2d u(std::cos(yaw), std::sin(yaw)), v(-std::sin(yaw), std::cos(yaw));
    Eigen::Vector2d pmin(INFINITY, INFINITY), pmax(-INFINITY, -INFINITY);
    for (const Coord& c : voxels) {
        const Eigen::Vector2d p = centre(c).head<2>();
        const Eigen::Vector2d q(p.dot(u), p.dot(v));
        pmin = pmin.cwiseMin(q);
        pmax = pmax.cwiseMax(q);
    }
    const Eigen::Vector2d mid = 0.5 * (pmin + pmax);
    o.oriented.center.head<2>() = mid.x() * u + mid.y() * v;
    o.oriented.center.z() = 0.5 * (o.bbox_min.z() + o.bbox_max.z());
    o.oriented.size = Eigen::Vector3d(pmax.x() - pmin.x() + s, pmax.y() - pmin.y() + s,
                                      o.bbox_max.z() - o.bbox_min.z());
    o.oriented.yaw_deg = yaw * 180.0 / M_PI;

    if (labels) {
        std::array<size_t, 256> votes{};
        auto acc = labels->getConstAccessor();
        for (const Coord& c : voxels) {
            int32_t value = 0;
            if (acc.probeValue(c, value) && value > 0 && value < 256) ++votes[value];
        }
        const auto best = std::max_element(votes.begin(), votes.end());
        if (*best > 0) {
            o.dominant_class = static_cast<core::SemanticClass>(best - votes.begin());
        }
    }
    return o;
}

}  // namespace

std::vector<ObjectVoxels> GroupObjects(const openvdb::BoolGrid& mask, ChangeKind kind,
                                       double voxel_size, int gap_voxels,
                                       const openvdb::Int32Grid* labels) {
    std::vector<Coord> coords;
    coords.reserve(mask.activeVoxelCount());
    for (auto on = mask.cbeginValueOn(); on; ++on) {
        if (on.isVoxelValue()) {
            coords.push_back(on.getCoord());
        } else {
            const openvdb::CoordBBox box = on.getBoundingBox();
            for (auto it = box.begin(); it; ++it) coords.push_back(*it);
        }
    }
    std::vector<ObjectVoxels> objects;
    for (std::vector<Coord>& voxels : geometry::GroupVoxels(coords, std::max(0, gap_voxels) + 1)) {
        // In x, y, z order: the sums of the statistics, and so their last bits, do not depend on
        // the order the mask was read in (one map, or tile by tile).
        std::sort(voxels.begin(), voxels.end());
        ObjectVoxels group;
        group.object = Describe(voxels, kind, voxel_size, labels);
        group.voxels = std::move(voxels);
        objects.push_back(std::move(group));
    }
    std::sort(objects.begin(), objects.end(), [](const auto& a, const auto& b) {
        if (a.object.voxels != b.object.voxels) return a.object.voxels > b.object.voxels;
        return a.voxels.front() < b.voxels.front();
    });
    return objects;
}

}  // namespace strata::change
