#include "strata/vehicles/LShapeFit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "strata/core/Error.hpp"

namespace strata::vehicles {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Extents of the points along two orthogonal axes.
struct Extents {
    double min1 = std::numeric_limits<double>::max(), max1 = -std::numeric_limits<double>::max();
    double min2 = std::numeric_limits<double>::max(), max2 = -std::numeric_limits<double>::max();
};

Extents Measure(const std::vector<Eigen::Vector2d>& points, const Eigen::Vector2d& e1,
                const Eigen::Vector2d& e2) {
    Extents x;
    for (const Eigen::Vector2d& p : points) {
        const double c1 = p.dot(e1), c2 = p.dot(e2);
        x.min1 = std::min(x.min1, c1), x.max1 = std::max(x.max1, c1);
        x.min2 = std::min(x.min2, c2), x.max2 = std::max(x.max2, c2);
    }
    return x;
}

// Variance criterion: each point belongs to the nearer of its two closest edges; the summed
// variance of the distances to those edges (lower is better).
double EdgeVariance(const std::vector<Eigen::Vector2d>& points, const Eigen::Vector2d& e1,
                    const Eigen::Vector2d& e2) {
    const Extents x = Measure(points, e1, e2);
    double n[2] = {0, 0}, sum[2] = {0, 0}, sum2[2] = {0, 0};
    for (const Eigen::Vector2d& p : points) {
        const double c1 = p.dot(e1), c2 = p.dot(e2);
        const double d1 = std::min(x.max1 - c1, c1 - x.min1);
        const double d2 = std::min(x.max2 - c2, c2 - x.min2);
        const int edge = d1 < d2 ? 0 : 1;
        const double d = edge == 0 ? d1 : d2;
        n[edge] += 1, sum[edge] += d, sum2[edge] += d * d;
    }
    double variance = 0.0;
    for (int e = 0; e < 2; ++e) {
        if (n[e] > 0) variance += sum2[e] / n[e] - (sum[e] / n[e]) * (sum[e] / n[e]);
    }
    return variance;
}

// Puts a yaw into [-pi/2, pi/2): a rectangle is the same turned by half a turn.
double WrapHalfTurn(double yaw) {
    while (yaw >= kPi / 2) yaw -= kPi;
    while (yaw < -kPi / 2) yaw += kPi;
    return yaw;
}

double PolygonArea(const std::vector<Eigen::Vector2d>& poly) {
    double twice = 0.0;
    for (size_t i = 0; i < poly.size(); ++i) {
        const Eigen::Vector2d& p = poly[i];
        const Eigen::Vector2d& q = poly[(i + 1) % poly.size()];
        twice += p.x() * q.y() - q.x() * p.y();
    }
    return 0.5 * std::abs(twice);
}

// Keeps the part of a convex polygon left of the directed edge a -> b (Sutherland-Hodgman).
std::vector<Eigen::Vector2d> ClipLeftOf(const std::vector<Eigen::Vector2d>& poly,
                                        const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    auto side = [&](const Eigen::Vector2d& p) {
        const Eigen::Vector2d e = b - a, d = p - a;
        return e.x() * d.y() - e.y() * d.x();
    };
    std::vector<Eigen::Vector2d> out;
    for (size_t i = 0; i < poly.size(); ++i) {
        const Eigen::Vector2d& p = poly[i];
        const Eigen::Vector2d& q = poly[(i + 1) % poly.size()];
        const double sp = side(p), sq = side(q);
        if (sp >= 0) out.push_back(p);
        if ((sp >= 0) != (sq >= 0)) out.push_back(p + (q - p) * (sp / (sp - sq)));
    }
    return out;
}

}  // namespace

double OverlapArea(const OrientedRect& a, const OrientedRect& b) {
    std::vector<Eigen::Vector2d> poly = a.Corners();
    const std::vector<Eigen::Vector2d> clip = b.Corners();
    for (size_t i = 0; i < clip.size() && !poly.empty(); ++i) {
        poly = ClipLeftOf(poly, clip[i], clip[(i + 1) % clip.size()]);
    }
    return poly.size() >= 3 ? PolygonArea(poly) : 0.0;
}

double BirdsEyeIoU(const OrientedRect& a, const OrientedRect& b) {
    const double inter = OverlapArea(a, b);
    const double uni = a.length * a.width + b.length * b.width - inter;
    return uni > 0.0 ? inter / uni : 0.0;
}

Eigen::Vector2d OrientedRect::Axis() const { return {std::cos(yaw_rad), std::sin(yaw_rad)}; }

bool OrientedRect::Contains(const Eigen::Vector2d& p, double margin) const {
    const Eigen::Vector2d a = Axis(), b(-a.y(), a.x()), d = p - center;
    return std::abs(d.dot(a)) <= 0.5 * length + margin &&
           std::abs(d.dot(b)) <= 0.5 * width + margin;
}

std::vector<Eigen::Vector2d> OrientedRect::Corners() const {
    const Eigen::Vector2d a = 0.5 * length * Axis(),
                          b = 0.5 * width * Eigen::Vector2d(-Axis().y(), Axis().x());
    return {center - a - b, center + a - b, center + a + b, center - a + b};
}

OrientedRect FitLShape(const std::vector<Eigen::Vector2d>& points, double step_deg) {
    if (points.size() < 2) throw InvalidArgumentError("L-shape fitting needs at least 2 points");
    if (!(step_deg > 0.0 && step_deg <= 45.0)) {
        throw InvalidArgumentError("L-shape heading step must be in (0, 45] degrees");
    }
    // Range: headings [0, 90) degrees; beyond, the two edges swap roles.
    double best_theta = 0.0, best = std::numeric_limits<double>::max();
    const int steps = static_cast<int>(std::ceil(90.0 / step_deg));
    for (int s = 0; s < steps; ++s) {
        const double theta = s * step_deg * kPi / 180.0;
        const Eigen::Vector2d e1(std::cos(theta), std::sin(theta)), e2(-e1.y(), e1.x());
        const double v = EdgeVariance(points, e1, e2);
        if (v < best) best = v, best_theta = theta;
    }
    const Eigen::Vector2d e1(std::cos(best_theta), std::sin(best_theta)), e2(-e1.y(), e1.x());
    const Extents x = Measure(points, e1, e2);
    OrientedRect rect;
    rect.center = 0.5 * (x.min1 + x.max1) * e1 + 0.5 * (x.min2 + x.max2) * e2;
    const double side1 = x.max1 - x.min1, side2 = x.max2 - x.min2;
    rect.length = std::max(side1, side2);
    rect.width = std::min(side1, side2);
    rect.yaw_rad = WrapHalfTurn(side1 >= side2 ? best_theta : best_theta + kPi / 2);
    return rect;
}

OrientedRect ExtendToCarSize(const OrientedRect& seen, const Eigen::Vector2d& viewpoint,
                             const CarSize& car) {
    OrientedRect rect = seen;
    // Seen from the front or back: the observed long side is the car's width.
    if (rect.length <= car.max_width_m && rect.width < car.min_width_m) {
        std::swap(rect.length, rect.width);
        rect.yaw_rad = WrapHalfTurn(rect.yaw_rad + kPi / 2);
    }
    const Eigen::Vector2d a = rect.Axis(), b(-a.y(), a.x());
    // Grows one side along `axis` to `target`, keeping the edge nearer the viewpoint.
    auto grow = [&](const Eigen::Vector2d& axis, double& side, double least, double target) {
        if (side >= least) return;
        const double towards_viewer = (viewpoint - rect.center).dot(axis) >= 0 ? 1.0 : -1.0;
        rect.center -= towards_viewer * 0.5 * (target - side) * axis;
        side = target;
    };
    grow(a, rect.length, car.min_length_m, car.length_m);
    grow(b, rect.width, car.min_width_m, car.width_m);
    return rect;
}

}  // namespace strata::vehicles
