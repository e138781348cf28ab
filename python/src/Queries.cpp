#include "Queries.hpp"

#include <cmath>
#include <limits>

#include "strata/columns/ColumnStats.hpp"
#include "strata/core/Endpoints.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"

namespace strata::python {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

py::ssize_t Size(size_t n) { return static_cast<py::ssize_t>(n); }

}  // namespace

py::dict QueryOccupancy(const core::VoxelMap& map, const py::array& points) {
    const std::vector<Eigen::Vector3d> p = PointsFromArray(points);
    std::vector<int8_t> state(p.size(), -1);
    std::vector<float> log_odds(p.size(), kNaN);
    std::vector<int32_t> label(p.size(), 0);
    std::vector<int32_t> hits(p.size(), 0);
    {
        py::gil_scoped_release release;
        const auto occupancy = map.occupancy->getConstAccessor();
        const auto labels = map.label->getConstAccessor();
        core::EndpointReader counts(map);
        for (size_t i = 0; i < p.size(); ++i) {
            if (!p[i].allFinite()) continue;
            const openvdb::Coord ijk = map.WorldToVoxel(p[i]);
            float value = 0.0f;
            if (!occupancy.probeValue(ijk, value)) continue;
            state[i] = value > 0.0f ? 1 : 0;
            log_odds[i] = value;
            label[i] = labels.getValue(ijk);
            hits[i] = counts.Hits(ijk);
        }
    }
    py::dict out;
    const py::ssize_t n = Size(p.size());
    out["state"] = ToArray(std::move(state), {n});
    out["log_odds"] = ToArray(std::move(log_odds), {n});
    out["label"] = ToArray(std::move(label), {n});
    out["hits"] = ToArray(std::move(hits), {n});
    return out;
}

py::dict QueryBox(const core::VoxelMap& map, const py::object& lo, const py::object& hi,
                  bool occupied_only) {
    const Eigen::Vector3d min = Vector3FromObject(lo, "lo");
    const Eigen::Vector3d max = Vector3FromObject(hi, "hi");
    if ((min.array() > max.array()).any()) {
        throw InvalidArgumentError("the box's lo must not exceed hi on any axis");
    }
    std::vector<int32_t> ijk;
    std::vector<double> center;
    std::vector<float> log_odds, weight;
    std::vector<int32_t> label, hits;
    {
        py::gil_scoped_release release;
        // Voxel (i, j, k) has its centre at (i + 0.5) * s: the index range of centres in [lo, hi].
        const double s = map.voxel_size;
        const auto first = [s](double v) { return static_cast<int>(std::ceil(v / s - 0.5)); };
        const auto last = [s](double v) { return static_cast<int>(std::floor(v / s - 0.5)); };
        const openvdb::CoordBBox box(openvdb::Coord(first(min.x()), first(min.y()), first(min.z())),
                                     openvdb::Coord(last(max.x()), last(max.y()), last(max.z())));
        const auto labels = map.label->getConstAccessor();
        const auto weights = map.label_weight->getConstAccessor();
        core::EndpointReader counts(map);
        // Active voxels only, never the dense box (docs/architecture.md, "Code style"); a tile
        // is expanded to voxels.
        for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
            openvdb::CoordBBox part = it.getBoundingBox();
            if (!part.hasOverlap(box)) continue;
            part.intersect(box);
            const float value = *it;
            if (occupied_only && value <= 0.0f) continue;
            for (auto c = part.begin(); c; ++c) {
                const openvdb::Coord v = *c;
                const Eigen::Vector3d centre = map.VoxelCenter(v);
                for (int a = 0; a < 3; ++a) {
                    ijk.push_back(v[a]);
                    center.push_back(centre[a]);
                }
                log_odds.push_back(value);
                label.push_back(labels.getValue(v));
                weight.push_back(weights.getValue(v));
                hits.push_back(counts.Hits(v));
            }
        }
    }
    const py::ssize_t n = Size(log_odds.size());
    py::dict out;
    out["ijk"] = ToArray(std::move(ijk), {n, 3});
    out["center"] = ToArray(std::move(center), {n, 3});
    out["log_odds"] = ToArray(std::move(log_odds), {n});
    out["label"] = ToArray(std::move(label), {n});
    out["label_weight"] = ToArray(std::move(weight), {n});
    out["hits"] = ToArray(std::move(hits), {n});
    return out;
}

py::dict QueryColumns(const core::VoxelMap& map, int window) {
    if (window < 0) throw InvalidArgumentError("window must be >= 0");
    columns::ColumnGrid grid;
    {
        py::gil_scoped_release release;
        grid = columns::ColumnGrid::FromMap(map);
        if (window > 0) grid = grid.Window(window);
    }
    const size_t w = static_cast<size_t>(grid.width()), h = static_cast<size_t>(grid.height());
    const size_t cells = w * h;
    std::vector<int64_t> points(cells);
    std::vector<int32_t> voxels(cells);
    std::vector<float> z_min(cells, kNaN), z_max(cells, kNaN), extent(cells, 0.0f);
    std::vector<int32_t> classes(cells * core::kNumClasses);
    const double s = map.voxel_size;
    for (size_t j = 0; j < h; ++j) {
        for (size_t i = 0; i < w; ++i) {
            const columns::ColumnStat& c =
                grid.At(grid.min_i() + static_cast<int>(i), grid.min_j() + static_cast<int>(j));
            const size_t cell = j * w + i;
            points[cell] = c.points;
            voxels[cell] = c.voxels;
            if (c.voxels > 0) {
                z_min[cell] = static_cast<float>(c.k_min * s);
                z_max[cell] = static_cast<float>((c.k_max + 1) * s);
                extent[cell] = static_cast<float>(c.extent_voxels() * s);
            }
            for (int k = 0; k < core::kNumClasses; ++k) {
                classes[cell * core::kNumClasses + static_cast<size_t>(k)] =
                    c.classes[static_cast<size_t>(k)];
            }
        }
    }
    py::dict out;
    const py::ssize_t rows = Size(h), cols = Size(w);
    out["x0"] = grid.min_i() * s;  // west edge of column i = 0 (map frame, metres)
    out["y0"] = grid.min_j() * s;  // south edge of row j = 0
    out["cell"] = s;
    out["points"] = ToArray(std::move(points), {rows, cols});
    out["voxels"] = ToArray(std::move(voxels), {rows, cols});
    out["z_min"] = ToArray(std::move(z_min), {rows, cols});
    out["z_max"] = ToArray(std::move(z_max), {rows, cols});
    out["extent"] = ToArray(std::move(extent), {rows, cols});
    out["classes"] = ToArray(std::move(classes), {rows, cols, core::kNumClasses});
    return out;
}

py::dict DescribeMap(const core::VoxelMap& map) {
    py::dict out;
    out["voxel"] = map.voxel_size;
    out["origin"] = py::make_tuple(map.origin.x(), map.origin.y(), map.origin.z());
    size_t occupied = 0;
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it > 0.0f) occupied += it.getVoxelCount();
    }
    out["observed_voxels"] = map.occupancy->activeVoxelCount();
    out["occupied_voxels"] = occupied;
    out["labelled_voxels"] = map.label->activeVoxelCount();
    return out;
}

}  // namespace strata::python
