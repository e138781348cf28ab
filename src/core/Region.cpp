#include "strata/core/Region.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "strata/core/Error.hpp"

namespace strata::core {

Region Region::Box(double x0, double y0, double x1, double y1) {
    if (!(std::isfinite(x0) && std::isfinite(y0) && std::isfinite(x1) && std::isfinite(y1)) ||
        !(x0 < x1) || !(y0 < y1)) {
        throw InvalidArgumentError("a region box needs finite x0 < x1 and y0 < y1");
    }
    Region r = Polygon({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}});
    r.is_box_ = true;
    return r;
}

Region Region::Polygon(std::vector<Eigen::Vector2d> vertices) {
    if (vertices.size() < 3) throw InvalidArgumentError("a region polygon needs 3 vertices");
    Region r;
    r.min_ = r.max_ = vertices.front();
    for (const Eigen::Vector2d& v : vertices) {
        if (!v.allFinite()) throw InvalidArgumentError("a region vertex is not finite");
        r.min_ = r.min_.cwiseMin(v);
        r.max_ = r.max_.cwiseMax(v);
    }
    if (!(r.min_.x() < r.max_.x()) || !(r.min_.y() < r.max_.y())) {
        throw InvalidArgumentError("a region polygon must enclose an area");
    }
    r.vertices_ = std::move(vertices);
    return r;
}

Region Region::Parse(const std::string& text) {
    std::vector<double> values;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        size_t used = 0;
        double v = 0.0;
        try {
            v = std::stod(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || item.find_first_not_of(" \t", used) != std::string::npos) {
            throw InvalidArgumentError("region '" + text + "': '" + item + "' is not a number");
        }
        values.push_back(v);
    }
    const auto bad = [&](const std::string& why) {
        return InvalidArgumentError("region '" + text + "': " + why +
                                    " (expected x0,y0,x1,y1 or a polygon x0,y0,x1,y1,x2,y2,...)");
    };
    try {
        if (values.size() == 4) return Box(values[0], values[1], values[2], values[3]);
        if (values.size() < 6 || values.size() % 2 != 0) throw bad("wrong number of values");
        std::vector<Eigen::Vector2d> vertices;
        for (size_t i = 0; i < values.size(); i += 2)
            vertices.emplace_back(values[i], values[i + 1]);
        return Polygon(std::move(vertices));
    } catch (const InvalidArgumentError& e) {
        if (std::string(e.what()).rfind("region '", 0) == 0) throw;
        throw bad(e.what());
    }
}

bool Region::Contains(double x, double y) const {
    if (x < min_.x() || x > max_.x() || y < min_.y() || y > max_.y()) return false;
    if (is_box_) return true;
    bool inside = false;
    for (size_t i = 0, j = vertices_.size() - 1; i < vertices_.size(); j = i++) {
        const Eigen::Vector2d& a = vertices_[i];
        const Eigen::Vector2d& b = vertices_[j];
        if ((a.y() > y) != (b.y() > y) &&
            x < (b.x() - a.x()) * (y - a.y()) / (b.y() - a.y()) + a.x()) {
            inside = !inside;
        }
    }
    return inside;
}

bool Region::MayOverlap(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const {
    return !(hi.x() < min_.x() || lo.x() > max_.x() || hi.y() < min_.y() || lo.y() > max_.y());
}

bool Region::Covers(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const {
    return is_box_ && lo.x() >= min_.x() && hi.x() <= max_.x() && lo.y() >= min_.y() &&
           hi.y() <= max_.y();
}

void Region::Clip(openvdb::BoolGrid& mask, double voxel_size) const {
    using LeafT = openvdb::BoolTree::LeafNodeType;
    mask.tree().voxelizeActiveTiles();
    std::vector<openvdb::Coord> drop;
    for (auto leaf = mask.tree().beginLeaf(); leaf; ++leaf) {
        const openvdb::CoordBBox box = leaf->getNodeBoundingBox();
        // Voxel centres of the leaf span [min + 0.5, max + 0.5] voxels.
        const Eigen::Vector2d lo((box.min().x() + 0.5) * voxel_size,
                                 (box.min().y() + 0.5) * voxel_size);
        const Eigen::Vector2d hi((box.max().x() + 0.5) * voxel_size,
                                 (box.max().y() + 0.5) * voxel_size);
        if (!MayOverlap(lo, hi)) {
            drop.push_back(leaf->origin());
            continue;
        }
        if (Covers(lo, hi)) continue;
        for (auto on = leaf->beginValueOn(); on; ++on) {
            const openvdb::Coord ijk = on.getCoord();
            if (!Contains((ijk.x() + 0.5) * voxel_size, (ijk.y() + 0.5) * voxel_size)) {
                on.setValueOff();
                on.setValue(false);
            }
        }
        if (leaf->isEmpty()) drop.push_back(leaf->origin());
    }
    for (const openvdb::Coord& origin : drop) {
        delete mask.tree().stealNode<LeafT>(origin, false, false);
    }
}

}  // namespace strata::core
