#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "strata/core/Error.hpp"
#include "strata/io/PoseFiles.hpp"

namespace strata::io {
namespace {

std::string ScanName(size_t index, double time_s) {
    return "scan " + std::to_string(index) + " (t = " + std::to_string(time_s) + " s)";
}

}  // namespace

std::vector<Eigen::Isometry3d> MatchPoses(const std::vector<StampedPose>& poses,
                                          const std::vector<double>& scan_times_s,
                                          double max_dt_s) {
    if (!(max_dt_s >= 0.0)) {
        throw InvalidArgumentError("MatchPoses: max_dt_s must be >= 0, got " +
                                   std::to_string(max_dt_s));
    }
    const size_t stamped = static_cast<size_t>(std::count_if(
        poses.begin(), poses.end(), [](const StampedPose& p) { return !std::isnan(p.time_s); }));
    std::vector<Eigen::Isometry3d> matched;
    matched.reserve(scan_times_s.size());

    // Poses without timestamps (KITTI): the i-th pose belongs to the i-th scan.
    if (stamped == 0) {
        if (poses.size() < scan_times_s.size()) {
            throw FormatError(ScanName(poses.size(), scan_times_s[poses.size()]) +
                              " has no pose: " + std::to_string(poses.size()) + " poses for " +
                              std::to_string(scan_times_s.size()) + " scans");
        }
        for (size_t i = 0; i < scan_times_s.size(); ++i) matched.push_back(poses[i].T);
        return matched;
    }
    if (stamped != poses.size()) {
        throw InvalidArgumentError("MatchPoses: only " + std::to_string(stamped) + " of " +
                                   std::to_string(poses.size()) + " poses have timestamps");
    }

    // Poses with timestamps: sort an index by time, then binary-search each scan's time.
    std::vector<size_t> order(poses.size());
    std::iota(order.begin(), order.end(), size_t{0});
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return poses[a].time_s < poses[b].time_s; });
    for (size_t i = 0; i < scan_times_s.size(); ++i) {
        const double t = scan_times_s[i];
        if (!std::isfinite(t)) throw FormatError(ScanName(i, t) + " has no finite time");
        const auto it = std::lower_bound(order.begin(), order.end(), t,
                                         [&](size_t k, double v) { return poses[k].time_s < v; });
        size_t best = order.size();  // index into `order`
        double best_dt = 0.0;
        const size_t hi = static_cast<size_t>(it - order.begin());
        for (size_t cand : {hi - 1, hi}) {  // hi - 1 wraps to a huge value when hi == 0
            if (cand >= order.size()) continue;
            const double dt = std::abs(poses[order[cand]].time_s - t);
            if (best == order.size() || dt < best_dt) {
                best = cand;
                best_dt = dt;
            }
        }
        if (best_dt > max_dt_s) {
            throw FormatError(
                ScanName(i, t) + " has no pose within " + std::to_string(max_dt_s) +
                " s: the nearest is at t = " + std::to_string(poses[order[best]].time_s) + " s");
        }
        matched.push_back(poses[order[best]].T);
    }
    return matched;
}

}  // namespace strata::io
