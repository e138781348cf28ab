#include <algorithm>

#include "MeshBuilders.hpp"
#include "ObjectGeometry.hpp"

namespace strata::sim::detail {
namespace {

std::vector<double> Cuts(double lo, double hi, const std::vector<Eigen::AlignedBox2d>& holes,
                         int axis) {
    std::vector<double> cuts = {lo, hi};
    for (const Eigen::AlignedBox2d& h : holes) {
        cuts.push_back(std::clamp(h.min()[axis], lo, hi));
        cuts.push_back(std::clamp(h.max()[axis], lo, hi));
    }
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(
        std::unique(cuts.begin(), cuts.end(), [](double a, double b) { return b - a < 1e-9; }),
        cuts.end());
    return cuts;
}

}  // namespace

double SlabTopZ(const SlabSpec& slab, double x, double y) {
    return slab.z + slab.slope.x() * x + slab.slope.y() * y;
}

bool SlabCovers(const SlabSpec& slab, double x, double y) {
    if (x < slab.min_xy.x() || x > slab.max_xy.x() || y < slab.min_xy.y() || y > slab.max_xy.y()) {
        return false;
    }
    for (const Eigen::AlignedBox2d& h : slab.holes) {
        if (h.contains(Eigen::Vector2d(x, y))) return false;
    }
    return true;
}

std::vector<Mesh> BuildSlabMeshes(const ObjectSpec& object, const SlabSpec& slab) {
    // The rectangle minus the holes, cut into cells at every hole edge (exact, no raster).
    const std::vector<double> X = Cuts(slab.min_xy.x(), slab.max_xy.x(), slab.holes, 0);
    const std::vector<double> Y = Cuts(slab.min_xy.y(), slab.max_xy.y(), slab.holes, 1);
    const size_t nx = X.size() - 1, ny = Y.size() - 1;
    auto solid = [&](size_t i, size_t j) {
        if (i >= nx || j >= ny) return false;  // also catches i or j wrapped below zero
        return SlabCovers(slab, 0.5 * (X[i] + X[i + 1]), 0.5 * (Y[j] + Y[j + 1]));
    };
    const double t = slab.thickness_m;
    auto top = [&](double x, double y) { return Eigen::Vector3d(x, y, SlabTopZ(slab, x, y)); };
    auto low = [&](double x, double y) { return Eigen::Vector3d(x, y, SlabTopZ(slab, x, y) - t); };

    Mesh top_mesh, side_mesh, bottom_mesh;
    for (size_t i = 0; i < nx; ++i) {
        for (size_t j = 0; j < ny; ++j) {
            if (!solid(i, j)) continue;
            const double x0 = X[i], x1 = X[i + 1], y0 = Y[j], y1 = Y[j + 1];
            AddQuad(top_mesh, top(x0, y0), top(x1, y0), top(x1, y1), top(x0, y1));
            if (slab.bottom_label != 0 && t > 0.0) {
                AddQuad(bottom_mesh, low(x0, y0), low(x0, y1), low(x1, y1), low(x1, y0));
            }
            if (t <= 0.0) continue;
            // Sides (kerbs, slab edges, hole rims) where a solid cell meets a gap or the border.
            if (!solid(i - 1, j))
                AddQuad(side_mesh, top(x0, y0), top(x0, y1), low(x0, y1), low(x0, y0));
            if (!solid(i + 1, j))
                AddQuad(side_mesh, top(x1, y0), low(x1, y0), low(x1, y1), top(x1, y1));
            if (!solid(i, j - 1))
                AddQuad(side_mesh, top(x0, y0), low(x0, y0), low(x1, y0), top(x1, y0));
            if (!solid(i, j + 1))
                AddQuad(side_mesh, top(x0, y1), top(x1, y1), low(x1, y1), low(x0, y1));
        }
    }
    std::vector<Mesh> meshes;
    const uint16_t labels[3] = {object.label, slab.side_label != 0 ? slab.side_label : object.label,
                                slab.bottom_label};
    Mesh* parts[3] = {&top_mesh, &side_mesh, &bottom_mesh};
    for (int k = 0; k < 3; ++k) {
        if (parts[k]->triangles.empty()) continue;
        parts[k]->label = labels[k];
        parts[k]->instance = static_cast<uint16_t>(object.id);
        parts[k]->reflectivity = object.reflectivity;
        meshes.push_back(std::move(*parts[k]));
    }
    return meshes;
}

}  // namespace strata::sim::detail
