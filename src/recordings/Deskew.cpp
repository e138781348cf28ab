#include "strata/recordings/Deskew.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "strata/core/Error.hpp"

namespace strata::recordings {
namespace {

// The motion is sampled this often across a sweep and interpolated between: a tf tree's or an
// odometry's trajectory is itself linear between its samples, so at 1 ms the interpolation adds
// well under a millimetre at road speeds.
constexpr double kKnotS = 1e-3;
// A deskewed sweep's rays start where the sensor was at their points' instants, to within this:
// the sweep is cut into runs of points over which the sensor moves at most twice as far, each
// with one ray origin in the middle (at 10 m/s about 10 runs to a 0.1 s sweep).
constexpr double kRayOriginToleranceM = 0.025;
// A sweep whose points' times span more than this is damaged (spinning LiDARs take 0.05-0.2 s).
constexpr double kMaxSweepS = 10.0;

// `values` moved to the positions `to` gives them (nothing for an empty array).
template <typename T>
void Reorder(std::vector<T>& values, const std::vector<size_t>& to) {
    if (values.empty()) return;
    std::vector<T> out(values.size());
    for (size_t j = 0; j < values.size(); ++j) out[to[j]] = std::move(values[j]);
    values = std::move(out);
}

}  // namespace

void RequireSweepTimes(const core::Scan& scan) {
    if (scan.times_s.empty()) return;
    const auto [lo, hi] = std::minmax_element(scan.times_s.begin(), scan.times_s.end());
    const double span = static_cast<double>(*hi) - static_cast<double>(*lo);
    if (!(span <= kMaxSweepS)) {  // NaN too
        char text[96];
        std::snprintf(text, sizeof(text), ": its points' times span %.3f s", span);
        throw FormatError(scan.source + text + "; a sweep takes a fraction of a second");
    }
}

void Deskew(core::Scan& scan, const SweepMotion& motion) {
    if (scan.times_s.empty()) return;
    RequireSweepTimes(scan);
    const auto [lo, hi] = std::minmax_element(scan.times_s.begin(), scan.times_s.end());
    const double t0 = *lo, span = static_cast<double>(*hi) - t0;
    // The sensor's poses relative to the stamp's at knots across the sweep.
    const size_t knots = static_cast<size_t>(span / kKnotS) + 2;
    std::vector<Eigen::Isometry3d> relative(knots);
    for (size_t k = 0; k < knots; ++k) {
        relative[k] = motion(t0 + span * static_cast<double>(k) / static_cast<double>(knots - 1));
    }
    // Runs of knot intervals over which the sensor moves at most twice the tolerance.
    std::vector<size_t> run_of(knots - 1);
    std::vector<core::RayOrigin> runs;
    for (size_t a = 0; a + 1 < knots;) {
        size_t b = a + 1;
        while (b + 1 < knots &&
               (relative[b + 1].translation() - relative[a].translation()).norm() <=
                   2.0 * kRayOriginToleranceM) {
            ++b;
        }
        std::fill(run_of.begin() + static_cast<ptrdiff_t>(a),
                  run_of.begin() + static_cast<ptrdiff_t>(b), runs.size());
        runs.push_back({0, 0.5 * (relative[a].translation() + relative[b].translation())});
        a = b;
    }
    // Each point moved by the pose of its instant, then the points stably ordered by run (a
    // counting sort).
    const size_t n = scan.points.size();
    const double scale = span > 0.0 ? static_cast<double>(knots - 1) / span : 0.0;
    std::vector<size_t> run(n);
    std::vector<size_t> count(runs.size() + 1, 0);
    for (size_t j = 0; j < n; ++j) {
        const double u = (static_cast<double>(scan.times_s[j]) - t0) * scale;
        const size_t k = std::min(static_cast<size_t>(u), knots - 2);
        scan.points[j] =
            core::Interpolate(relative[k], relative[k + 1], u - static_cast<double>(k)) *
            scan.points[j];
        run[j] = run_of[k];
        ++count[run[j] + 1];
    }
    scan.ray_origins.clear();
    for (size_t r = 0; r < runs.size(); ++r) {
        // Runs no point fell into (a gap in the sweep's times) are left out.
        if (count[r + 1] > 0) scan.ray_origins.push_back({count[r], runs[r].origin});
        count[r + 1] += count[r];
    }
    std::vector<size_t> to(n);
    for (size_t j = 0; j < n; ++j) to[j] = count[run[j]]++;
    Reorder(scan.points, to);
    Reorder(scan.intensity, to);
    Reorder(scan.labels, to);
    Reorder(scan.instances, to);
    scan.times_s.clear();
}

void DeskewAlong(core::Scan& scan, const std::vector<double>& times_s,
                 const std::vector<Eigen::Isometry3d>& poses) {
    const Eigen::Isometry3d T_stamp_world = scan.T_world_sensor.inverse();
    Deskew(scan, [&](double tau) {
        return Eigen::Isometry3d(T_stamp_world * core::PoseAt(times_s, poses, scan.time_s + tau));
    });
}

}  // namespace strata::recordings
