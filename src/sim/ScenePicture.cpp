#include "strata/sim/ScenePicture.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <utility>

#include "strata/core/Error.hpp"
#include "strata/sim/KittiIds.hpp"
#include "strata/sim/Simulator.hpp"

namespace strata::sim {
namespace {

class Canvas {
public:
    Canvas(Picture& p, const Eigen::Vector2d& min_xy, double pixel_m)
        : p_(p), min_(min_xy), pixel_m_(pixel_m) {}
    void Dot(const Eigen::Vector2d& xy, int radius, core::Rgb c) {
        const int cx = Column(xy.x()), cy = Row(xy.y());
        for (int y = cy - radius; y <= cy + radius; ++y) {
            for (int x = cx - radius; x <= cx + radius; ++x) Set(x, y, c);
        }
    }
    void Line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, core::Rgb c) {
        const int steps = 1 + static_cast<int>((b - a).norm() / pixel_m_);
        for (int i = 0; i <= steps; ++i) Dot(a + (b - a) * i / steps, 0, c);
    }
    void Box(const BoxTruth& box, core::Rgb c) {
        const double yaw = box.yaw_deg * M_PI / 180.0;
        const Eigen::Vector2d ax(std::cos(yaw), std::sin(yaw)), ay(-ax.y(), ax.x());
        const Eigen::Vector2d o = box.center.head<2>();
        const double hx = 0.5 * box.size.x(), hy = 0.5 * box.size.y();
        const Eigen::Vector2d k[4] = {o - hx * ax - hy * ay, o + hx * ax - hy * ay,
                                      o + hx * ax + hy * ay, o - hx * ax + hy * ay};
        for (int i = 0; i < 4; ++i) Line(k[i], k[(i + 1) % 4], c);
    }

private:
    int Column(double x) const { return static_cast<int>(std::floor((x - min_.x()) / pixel_m_)); }
    int Row(double y) const {
        return p_.height - 1 - static_cast<int>(std::floor((y - min_.y()) / pixel_m_));
    }
    void Set(int x, int y, core::Rgb c) {
        if (x < 0 || y < 0 || x >= p_.width || y >= p_.height) return;
        uint8_t* px = &p_.rgb[(size_t(y) * size_t(p_.width) + size_t(x)) * 3];
        px[0] = c.r;
        px[1] = c.g;
        px[2] = c.b;
    }

    Picture& p_;
    Eigen::Vector2d min_;
    double pixel_m_;
};

// The solid enclosing a point: looking up from inside a wall, box or pole one crosses the
// faces of that object an odd number of times (its bottom may be open, its top is closed).
// Counting one object only keeps faces of other objects that touch it out of the count.
std::optional<RayHit> SolidAround(const Scene& scene, const Simulator& simulator,
                                  const Eigen::Vector3d& point) {
    const auto first = simulator.CastRay(point, Eigen::Vector3d::UnitZ(), 1e3);
    if (!first || !scene.meshes[first->mesh].solid) return std::nullopt;
    int crossings = 0;
    Eigen::Vector3d o = point;
    for (int step = 0; step < 64; ++step) {
        const auto hit = simulator.CastRay(o, Eigen::Vector3d::UnitZ(), 1e3);
        if (!hit) break;
        crossings += hit->instance == first->instance ? 1 : 0;
        o = hit->point + Eigen::Vector3d(0, 0, 1e-4);
    }
    return crossings % 2 == 1 ? first : std::nullopt;
}

}  // namespace

void PictureConfig::Validate() const {
    if (!(pixel_m > 0.0) || !(margin_m >= 0.0) || max_size_px < 16) {
        throw InvalidArgumentError("picture: pixel_m > 0, margin_m >= 0, max_size_px >= 16");
    }
}

Picture RenderScenePicture(const Scene& scene, const Simulator& simulator,
                           const std::vector<ScanPose>& poses, const PictureConfig& config) {
    config.Validate();
    Picture p;
    if (scene.bounds.isEmpty()) return p;
    const Eigen::Vector2d min_xy = scene.bounds.min().head<2>().array() - config.margin_m;
    const Eigen::Vector2d extent = scene.bounds.sizes().head<2>().array() + 2 * config.margin_m;
    const double pixel_m = std::max(config.pixel_m, extent.maxCoeff() / config.max_size_px);
    p.width = std::max(1, static_cast<int>(std::ceil(extent.x() / pixel_m)));
    p.height = std::max(1, static_cast<int>(std::ceil(extent.y() / pixel_m)));
    p.rgb.assign(size_t(p.width) * size_t(p.height) * 3, 24);
    const bool cut = !std::isnan(config.cut_z);
    const double z_top = cut ? config.cut_z : scene.bounds.max().z() + 1.0;
    const double z_span = std::max(1.0, z_top - scene.bounds.min().z());
    // Range: picture rows; one downward ray per pixel.
    tbb::parallel_for(tbb::blocked_range<int>(0, p.height), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y != r.end(); ++y) {
            for (int x = 0; x < p.width; ++x) {
                const Eigen::Vector3d origin(min_xy.x() + (x + 0.5) * pixel_m,
                                             min_xy.y() + (p.height - y - 0.5) * pixel_m, z_top);
                // Cut inside a solid (a wall spanning the cut height): draw the solid, darker.
                const std::optional<RayHit> solid =
                    cut ? SolidAround(scene, simulator, origin) : std::nullopt;
                const auto hit =
                    solid ? solid : simulator.CastRay(origin, -Eigen::Vector3d::UnitZ(), 1e4);
                if (!hit) continue;
                // Class colour, darker on steep faces and lower down.
                const core::Rgb c = kitti::Color(hit->label);
                const double shade = solid ? 0.6
                                           : (0.55 + 0.45 * std::abs(hit->normal.z())) *
                                                 (0.75 + 0.25 * (1.0 - hit->range_m / z_span));
                uint8_t* px = &p.rgb[(size_t(y) * size_t(p.width) + size_t(x)) * 3];
                px[0] = static_cast<uint8_t>(std::clamp(c.r * shade, 0.0, 255.0));
                px[1] = static_cast<uint8_t>(std::clamp(c.g * shade, 0.0, 255.0));
                px[2] = static_cast<uint8_t>(std::clamp(c.b * shade, 0.0, 255.0));
            }
        }
    });
    Canvas canvas(p, min_xy, pixel_m);
    if (config.draw_edits) {
        for (const EditTruth& e : scene.truth.edits) {
            canvas.Box(e.box, e.change == "added" ? core::Rgb{0, 255, 0} : core::Rgb{255, 0, 0});
        }
    }
    if (config.draw_traffic) {
        for (const ActorSpec& a : scene.actors) {
            const core::Rgb c = kitti::Color(ActorLabel(a.type, true));
            for (size_t i = 1; i < a.path.size(); ++i) {
                canvas.Line(a.path[i - 1].head<2>(), a.path[i].head<2>(), c);
            }
            canvas.Dot(a.path.front().head<2>(), 1, c);
            // Where it stands: boxed in its standing class's colour.
            const core::Rgb standing = kitti::Color(ActorLabel(a.type, false));
            for (const auto& [stands, t_s] :
                 {std::pair{a.before, a.start_s}, std::pair{a.after, a.EndS()}}) {
                if (!stands) continue;
                const Eigen::Isometry3d T = ActorPoseAt(a, t_s).value().T_world_actor;
                BoxTruth box;
                box.center = T.translation();
                box.size = ActorSize(a.type);
                box.yaw_deg = std::atan2(T.linear()(1, 0), T.linear()(0, 0)) * 180.0 / M_PI;
                canvas.Box(box, standing);
            }
        }
    }
    if (config.draw_trajectory) {
        for (const ScanPose& pose : poses) {
            canvas.Dot(pose.T_world_sensor.translation().head<2>(), 2, {255, 30, 30});
        }
    }
    return p;
}

}  // namespace strata::sim
