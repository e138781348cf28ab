#include "CoarseSearch.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace strata::registration::test {

namespace {

// One point (x, y) per cell of `cell_m` among the points in the height and range bands.
std::vector<Eigen::Vector2d> VotingPoints(const std::vector<Eigen::Vector3d>& points,
                                          const CoarseSearchConfig& config) {
    std::map<std::pair<long, long>, Eigen::Vector2d> cells;
    for (const Eigen::Vector3d& p : points) {
        const double r = p.norm();
        if (!p.allFinite() || r < config.min_range_m || r > config.max_range_m) continue;
        if (p.z() < config.min_z_m || p.z() > config.max_z_m) continue;
        cells.emplace(std::make_pair(long(std::floor(p.x() / config.point_cell_m)),
                                     long(std::floor(p.y() / config.point_cell_m))),
                      p.head<2>());
    }
    std::vector<Eigen::Vector2d> out;
    for (const auto& cell : cells) out.push_back(cell.second);
    return out;
}

}  // namespace

std::vector<CoarseCandidate> CoarseSearch(const std::vector<Eigen::Vector3d>& target,
                                          const std::vector<Eigen::Vector3d>& source, size_t count,
                                          const CoarseSearchConfig& config) {
    const std::vector<Eigen::Vector2d> t = VotingPoints(target, config);
    const std::vector<Eigen::Vector2d> s = VotingPoints(source, config);
    const long half = long(std::ceil(config.max_shift_m / config.vote_cell_m));
    const long side = 2 * half + 1;
    const auto yaws = size_t(std::lround(360.0 / config.yaw_step_deg));
    std::vector<CoarseCandidate> best(yaws);
    tbb::parallel_for(size_t(0), yaws, [&](size_t k) {
        const double yaw = -180.0 + double(k) * config.yaw_step_deg;
        const Eigen::Rotation2Dd R(yaw * M_PI / 180.0);
        std::vector<int> votes(size_t(side * side), 0);
        for (const Eigen::Vector2d& sp : s) {
            const Eigen::Vector2d moved = R * sp;
            for (const Eigen::Vector2d& tp : t) {
                const Eigen::Vector2d d = tp - moved;
                const long ix = long(std::floor(d.x() / config.vote_cell_m)) + half;
                const long iy = long(std::floor(d.y() / config.vote_cell_m)) + half;
                if (ix < 0 || iy < 0 || ix >= side || iy >= side) continue;
                ++votes[size_t(iy * side + ix)];
            }
        }
        const auto top = size_t(std::max_element(votes.begin(), votes.end()) - votes.begin());
        CoarseCandidate& c = best[k];
        c.votes = votes[top];
        c.T_target_source.linear() =
            Eigen::AngleAxisd(yaw * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
        c.T_target_source.translation() =
            Eigen::Vector3d((double(long(top) % side - half) + 0.5) * config.vote_cell_m,
                            (double(long(top) / side - half) + 0.5) * config.vote_cell_m, 0.0);
    });
    std::stable_sort(
        best.begin(), best.end(),
        [](const CoarseCandidate& a, const CoarseCandidate& b) { return a.votes > b.votes; });
    best.resize(std::min(count, best.size()));
    return best;
}

}  // namespace strata::registration::test
