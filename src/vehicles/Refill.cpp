// Clearing a vehicle, the Embree line-of-sight check, and the ground refill under the box.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "OcclusionScene.hpp"
#include "strata/core/Labels.hpp"
#include "strata/vehicles/VehicleStages.hpp"

namespace strata::vehicles {

namespace {

// The x/y voxel columns whose centres lie in a rectangle grown by `margin`.
template <typename Fn>
void ForEachColumn(const core::VoxelMap& map, const OrientedRect& rect, double margin, Fn&& fn) {
    double x0 = std::numeric_limits<double>::max(), y0 = x0, x1 = -x0, y1 = -x0;
    for (const Eigen::Vector2d& c : rect.Corners()) {
        x0 = std::min(x0, c.x()), y0 = std::min(y0, c.y());
        x1 = std::max(x1, c.x()), y1 = std::max(y1, c.y());
    }
    const double s = map.voxel_size;
    const int i0 = int(std::floor((x0 - margin) / s)), i1 = int(std::floor((x1 + margin) / s));
    const int j0 = int(std::floor((y0 - margin) / s)), j1 = int(std::floor((y1 + margin) / s));
    for (int j = j0; j <= j1; ++j) {
        for (int i = i0; i <= i1; ++i) {
            const Eigen::Vector2d centre((i + 0.5) * s, (j + 0.5) * s);
            if (rect.Contains(centre, margin)) fn(i, j, centre);
        }
    }
}

// Removes a voxel from every grid of the map.
struct Eraser {
    explicit Eraser(core::VoxelMap& map)
        : occupancy(map.occupancy->getAccessor()),
          label(map.label->getAccessor()),
          weight(map.label_weight->getAccessor()),
          endpoints(map.endpoints->getAccessor()) {}
    void Erase(const openvdb::Coord& c) {
        occupancy.setValueOff(c, 0.0F);
        label.setValueOff(c, 0);
        weight.setValueOff(c, 0.0F);
        endpoints.setValueOff(c, 0);
    }
    openvdb::FloatGrid::Accessor occupancy;
    openvdb::Int32Grid::Accessor label;
    openvdb::FloatGrid::Accessor weight;
    openvdb::Int32Grid::Accessor endpoints;
};

// Writes occupied ground at a voxel, its height `z` as the voxel's point mean (its hit count, no
// points, is kept).
struct GroundWriter {
    GroundWriter(core::VoxelMap& map, float log_odds)
        : map(map),
          occupancy(map.occupancy->getAccessor()),
          label(map.label->getAccessor()),
          weight(map.label_weight->getAccessor()),
          endpoints(map.endpoints->getAccessor()),
          log_odds(log_odds) {}
    void Write(const openvdb::Coord& c, float z) {
        occupancy.setValue(c, log_odds);
        label.setValue(c, static_cast<int32_t>(core::SemanticClass::kGround));
        weight.setValue(c, 1.0F);
        const double offset = static_cast<double>(z) - map.VoxelCenter(c).z();
        const int32_t hits = core::endpoint::Hits(endpoints.getValue(c));
        endpoints.setValue(
            c, core::endpoint::Pack(hits, Eigen::Vector3d(0.0, 0.0, offset), map.voxel_size));
    }
    const core::VoxelMap& map;
    openvdb::FloatGrid::Accessor occupancy;
    openvdb::Int32Grid::Accessor label;
    openvdb::FloatGrid::Accessor weight;
    openvdb::Int32Grid::Accessor endpoints;
    float log_odds;
};

// Calls fn(voxel, value) for each active voxel of `grid` in the x/y box `columns`.
template <typename GridT, typename Fn>
void ForEachVoxelIn(const GridT& grid, const openvdb::CoordBBox& columns, Fn&& fn) {
    for (auto it = grid.cbeginValueOn(); it; ++it) {
        const openvdb::CoordBBox voxels = it.getBoundingBox();
        for (auto v = voxels.begin(); v; ++v) {
            const openvdb::Coord c = *v;
            const bool inside = c.x() >= columns.min().x() && c.x() <= columns.max().x() &&
                                c.y() >= columns.min().y() && c.y() <= columns.max().y();
            if (inside) fn(c, *it);
        }
    }
}

// z = a + b dx + c dy around `centre`, by least squares with Huber weights (IRLS): a few ring
// columns on a kerb or a neighbouring car's tyre do not tilt the plane.
Eigen::Vector3d FitGroundPlane(const std::vector<Eigen::Vector3d>& samples) {
    constexpr double kHuberM = 0.05;
    constexpr int kIterations = 5;
    std::vector<double> w(samples.size(), 1.0);
    Eigen::Vector3d plane = Eigen::Vector3d::Zero();
    for (int it = 0; it < kIterations; ++it) {
        Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
        Eigen::Vector3d b = Eigen::Vector3d::Zero();
        for (size_t k = 0; k < samples.size(); ++k) {
            const Eigen::Vector3d row(1.0, samples[k].x(), samples[k].y());
            A += w[k] * row * row.transpose();
            b += w[k] * row * samples[k].z();
        }
        plane = A.ldlt().solve(b);
        for (size_t k = 0; k < samples.size(); ++k) {
            const double r = std::abs(
                plane.dot(Eigen::Vector3d(1.0, samples[k].x(), samples[k].y())) - samples[k].z());
            w[k] = r <= kHuberM ? 1.0 : kHuberM / r;
        }
    }
    return plane;
}

}  // namespace

size_t ClearVehicle(core::VoxelMap& map, const VehicleObject& object, const GroundField& ground,
                    const openvdb::MaskGrid& kept, openvdb::Int32Grid& cleared,
                    const VehicleConfig& config) {
    const Vehicle& v = object.vehicle;
    const double s = map.voxel_size;
    auto occupancy = map.occupancy->getConstAccessor();
    auto keep = kept.getConstAccessor();
    auto mark = cleared.getAccessor();
    std::vector<openvdb::Coord> doomed = object.voxels;
    ForEachColumn(map, v.footprint, 0.0, [&](int i, int j, const Eigen::Vector2d&) {
        double g = ground.Height(i, j);
        if (std::isnan(g)) g = v.ground_z;
        const int k0 = int(std::floor((g + config.clear_min_height_m) / s)) - 1;
        const int k1 = int(std::floor((v.ground_z + v.height + config.clear_min_height_m) / s));
        for (int k = k0; k <= k1; ++k) {
            const openvdb::Coord c(i, j, k);
            if (!(occupancy.getValue(c) > 0.0F) || !occupancy.isValueOn(c) || keep.isValueOn(c)) {
                continue;
            }
            if (map.PointMean(c).z() - g >= config.clear_min_height_m) doomed.push_back(c);
        }
    });
    Eraser eraser(map);
    size_t count = 0;
    for (const openvdb::Coord& c : doomed) {
        if (mark.isValueOn(c)) continue;  // listed twice (object voxel inside the box)
        eraser.Erase(c);
        mark.setValueOn(c, v.id);
        ++count;
    }
    return count;
}

struct RayCheck::Impl {
    Impl(std::vector<openvdb::Coord> occluders, double voxel_size)
        : scene(occluders, voxel_size), voxel_size(voxel_size) {}
    detail::OcclusionScene scene;
    double voxel_size;
    std::vector<Eigen::Vector3d> origins;
    double range_m = 0.0;
    size_t max_origins = 0;
};

RayCheck::RayCheck(const core::VoxelMap& map, const GroundField& ground,
                   std::vector<Eigen::Vector3d> origins_map, const Eigen::AlignedBox3d& region,
                   const VehicleConfig& config) {
    std::vector<openvdb::Coord> occluders;
    if (!region.isEmpty()) {
        const openvdb::CoordBBox box(map.WorldToVoxel(region.min()),
                                     map.WorldToVoxel(region.max()));
        for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
            if (*it <= 0.0F || !it.isVoxelValue() || !box.isInside(it.getCoord())) continue;
            const openvdb::Coord c = it.getCoord();
            const double g = ground.Height(c.x(), c.y());
            if (std::isnan(g) || map.PointMean(c).z() - g > config.min_voxel_height_m) {
                occluders.push_back(c);
            }
        }
    }
    impl_ = std::make_unique<Impl>(std::move(occluders), map.voxel_size);
    impl_->origins = std::move(origins_map);
    impl_->range_m = config.ray_range_m;
    impl_->max_origins = config.max_origins;
}

RayCheck::~RayCheck() = default;
RayCheck::RayCheck(RayCheck&&) noexcept = default;
RayCheck& RayCheck::operator=(RayCheck&&) noexcept = default;

size_t RayCheck::faces() const { return impl_->scene.faces(); }

bool RayCheck::Visible(const Eigen::Vector3d& point_map) const {
    std::vector<std::pair<double, size_t>> near;
    const double range2 = impl_->range_m * impl_->range_m;
    for (size_t k = 0; k < impl_->origins.size(); ++k) {
        const double d2 = (impl_->origins[k] - point_map).squaredNorm();
        if (d2 <= range2) near.emplace_back(d2, k);
    }
    const size_t tries = std::min(near.size(), impl_->max_origins);
    std::partial_sort(near.begin(), near.begin() + tries, near.end());
    for (size_t t = 0; t < tries; ++t) {
        const Eigen::Vector3d& o = impl_->origins[near[t].second];
        if (!impl_->scene.Blocked(o, point_map, 0.5 * impl_->voxel_size)) return true;
    }
    return false;
}

void RefillGround(core::VoxelMap& map, Vehicle& vehicle, const GroundField& ground,
                  const RayCheck* check, openvdb::FloatGrid& refilled,
                  const VehicleConfig& config) {
    const double s = map.voxel_size;
    const OrientedRect& box = vehicle.footprint;

    // Step 1: the plane through the measured ground of the ring around the box.
    std::vector<Eigen::Vector3d> ring;
    ForEachColumn(map, box, config.ring_gap_m + config.ring_width_m,
                  [&](int i, int j, const Eigen::Vector2d& c) {
                      if (box.Contains(c, config.ring_gap_m) || !ground.Measured(i, j)) return;
                      const Eigen::Vector2d d = c - box.center;
                      ring.emplace_back(d.x(), d.y(), ground.Height(i, j));
                  });
    vehicle.ring_cells = ring.size();
    const bool plane_ok = ring.size() >= config.min_ring_cells;
    if (plane_ok) vehicle.ground_plane = FitGroundPlane(ring);

    // Step 2: cells under the box that are not ground yet, and whether the map saw them empty.
    struct Cell {
        openvdb::Coord ijk;
        double z;
        bool seen_empty;
        bool visible = false;
    };
    std::vector<Cell> cells;
    auto occupancy = map.occupancy->getConstAccessor();
    // A quarter voxel of margin: columns on the box edge count whatever the rounding.
    ForEachColumn(map, box, 0.25 * s, [&](int i, int j, const Eigen::Vector2d& c) {
        const Eigen::Vector2d d = c - box.center;
        const double z = plane_ok ? vehicle.ground_plane.dot(Eigen::Vector3d(1.0, d.x(), d.y()))
                                  : ground.Height(i, j);
        if (std::isnan(z)) return;
        const openvdb::Coord ijk(i, j, int(std::floor(z / s)));
        for (int dk = -1; dk <= 1; ++dk) {
            const openvdb::Coord n = ijk.offsetBy(0, 0, dk);
            if (occupancy.getValue(n) > 0.0F && std::abs(map.PointMean(n).z() - z) <= s) {
                ++vehicle.already_ground_cells;
                return;
            }
        }
        cells.push_back({ijk, z, occupancy.isValueOn(ijk) && occupancy.getValue(ijk) < 0.0F});
    });

    // Step 3: rays only for cells seen empty (an unknown cell has nothing saying it is empty).
    if (check != nullptr) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, cells.size(), 16),
                          [&](const tbb::blocked_range<size_t>& r) {
                              for (size_t k = r.begin(); k != r.end(); ++k) {
                                  Cell& c = cells[k];
                                  if (!c.seen_empty) continue;
                                  const Eigen::Vector3d p = map.VoxelCenter(c.ijk);
                                  c.visible = check->Visible({p.x(), p.y(), c.z});
                              }
                          });
    }

    // Step 4: write occupied ground where the cell was hidden (or never seen).
    GroundWriter writer(map, config.refill_log_odds);
    auto mark = refilled.getAccessor();
    for (const Cell& c : cells) {
        // Without a ray check, a cell seen empty is trusted to be a gap.
        if (c.seen_empty && (check == nullptr || c.visible)) {
            ++vehicle.refused_cells;
            continue;
        }
        // The height as `refilled` holds it, so that ApplyEdits writes the same voxel.
        const auto z = static_cast<float>(c.z);
        writer.Write(c.ijk, z);
        mark.setValue(c.ijk, z);
        ++vehicle.refilled_cells;
    }
}

void ApplyEdits(core::VoxelMap& map, const openvdb::Int32Grid& cleared,
                const openvdb::FloatGrid& refilled, const openvdb::CoordBBox& columns,
                const VehicleConfig& config) {
    Eraser eraser(map);
    ForEachVoxelIn(cleared, columns, [&](const openvdb::Coord& c, int32_t) { eraser.Erase(c); });
    GroundWriter writer(map, config.refill_log_odds);
    ForEachVoxelIn(refilled, columns,
                   [&](const openvdb::Coord& c, float z) { writer.Write(c, z); });
}

}  // namespace strata::vehicles
