#include "strata/walls/Clustering.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace strata::walls {

std::vector<int> Dbscan(const std::vector<openvdb::Coord>& voxels, double eps_voxels,
                        int min_points) {
    if (!(eps_voxels >= 1.0)) throw std::invalid_argument("DBSCAN: eps must be >= 1 voxel");
    if (min_points < 1) throw std::invalid_argument("DBSCAN: min_points must be >= 1");
    // The grid is the index: voxel -> position in `voxels` + 1 (0 = background).
    auto index = openvdb::Int32Grid::create(0);
    {
        auto acc = index->getAccessor();
        for (size_t n = 0; n < voxels.size(); ++n) {
            acc.setValue(voxels[n], static_cast<int32_t>(n + 1));
        }
    }
    const int r = static_cast<int>(std::floor(eps_voxels));
    std::vector<openvdb::Coord> offsets;
    for (int dz = -r; dz <= r; ++dz) {
        for (int dy = -r; dy <= r; ++dy) {
            for (int dx = -r; dx <= r; ++dx) {
                if (dx * dx + dy * dy + dz * dz <= eps_voxels * eps_voxels) {
                    offsets.emplace_back(dx, dy, dz);
                }
            }
        }
    }
    auto acc = index->getConstAccessor();
    std::vector<int32_t> neighbours;
    auto neighbours_of = [&](const openvdb::Coord& c) {
        neighbours.clear();
        for (const openvdb::Coord& o : offsets) {
            const int32_t n = acc.getValue(c + o);
            if (n > 0) neighbours.push_back(n - 1);
        }
    };
    constexpr int kUnvisited = -2;
    std::vector<int> label(voxels.size(), kUnvisited);
    std::vector<int32_t> frontier;
    int next = 0;
    for (size_t seed = 0; seed < voxels.size(); ++seed) {
        if (label[seed] != kUnvisited) continue;
        neighbours_of(voxels[seed]);
        if (static_cast<int>(neighbours.size()) < min_points) {
            label[seed] = kNoise;  // may become a border voxel of a later cluster
            continue;
        }
        const int cluster = next++;
        label[seed] = cluster;
        frontier.assign(neighbours.begin(), neighbours.end());
        while (!frontier.empty()) {
            const int32_t q = frontier.back();
            frontier.pop_back();
            if (label[q] == kNoise) label[q] = cluster;  // border voxel
            if (label[q] != kUnvisited) continue;
            label[q] = cluster;
            neighbours_of(voxels[q]);
            if (static_cast<int>(neighbours.size()) >= min_points) {
                for (int32_t n : neighbours) {
                    if (label[n] == kUnvisited || label[n] == kNoise) frontier.push_back(n);
                }
            }
        }
    }
    return label;
}

std::vector<int> KMeans(const std::vector<Eigen::Vector3d>& points, int k, uint64_t seed,
                        int max_iterations) {
    const size_t n = points.size();
    std::vector<int> assignment(n, 0);
    if (n == 0) return assignment;
    k = std::clamp(k, 1, static_cast<int>(n));
    if (k == 1) return assignment;
    std::mt19937_64 rng(seed);
    // k-means++: each next centre drawn with probability proportional to the squared distance
    // to the nearest centre chosen so far.
    std::vector<Eigen::Vector3d> centres;
    centres.push_back(points[std::uniform_int_distribution<size_t>(0, n - 1)(rng)]);
    std::vector<double> d2(n, std::numeric_limits<double>::max());
    while (static_cast<int>(centres.size()) < k) {
        double total = 0.0;
        for (size_t i = 0; i < n; ++i) {
            d2[i] = std::min(d2[i], (points[i] - centres.back()).squaredNorm());
            total += d2[i];
        }
        if (total <= 0.0) break;  // fewer distinct points than k
        double pick = std::uniform_real_distribution<double>(0.0, total)(rng);
        size_t chosen = n - 1;
        for (size_t i = 0; i < n; ++i) {
            pick -= d2[i];
            if (pick <= 0.0) {
                chosen = i;
                break;
            }
        }
        centres.push_back(points[chosen]);
    }
    // Lloyd's iterations with Hamerly's bounds (2010): the same assignments as plain Lloyd, but a
    // point is only compared with every centre when its distance bounds cannot rule a change
    // out. upper[i] bounds the distance to its centre from above, lower[i] the distance to any
    // other centre from below.
    const int kk = static_cast<int>(centres.size());
    std::vector<double> upper(n), lower(n), half_gap(kk), moved(kk);
    const auto nearest_two = [&](size_t i) {
        double d1 = std::numeric_limits<double>::max(), d2nd = d1;
        int best = 0;
        for (int c = 0; c < kk; ++c) {
            const double d = (points[i] - centres[c]).norm();
            if (d < d1) {
                d2nd = d1;
                d1 = d;
                best = c;
            } else if (d < d2nd) {
                d2nd = d;
            }
        }
        assignment[i] = best;
        upper[i] = d1;
        lower[i] = d2nd;
    };
    for (size_t i = 0; i < n; ++i) nearest_two(i);
    std::vector<Eigen::Vector3d> sums(kk);
    std::vector<size_t> counts(kk);
    for (int iteration = 0; iteration < max_iterations; ++iteration) {
        // Move each centre to the mean of its points.
        std::fill(sums.begin(), sums.end(), Eigen::Vector3d::Zero());
        std::fill(counts.begin(), counts.end(), 0);
        for (size_t i = 0; i < n; ++i) {
            sums[assignment[i]] += points[i];
            ++counts[assignment[i]];
        }
        double most = 0.0, second = 0.0;
        int most_moved = -1;
        for (int c = 0; c < kk; ++c) {
            const Eigen::Vector3d next =
                counts[c] > 0 ? Eigen::Vector3d(sums[c] / static_cast<double>(counts[c]))
                              : centres[c];
            moved[c] = (next - centres[c]).norm();
            centres[c] = next;
            if (moved[c] > most) {
                second = most;
                most = moved[c];
                most_moved = c;
            } else if (moved[c] > second) {
                second = moved[c];
            }
        }
        if (most == 0.0) break;  // converged: no centre moved, so no point changes
        for (size_t i = 0; i < n; ++i) {
            upper[i] += moved[assignment[i]];
            lower[i] -= assignment[i] == most_moved ? second : most;
        }
        for (int c = 0; c < kk; ++c) {
            double gap = std::numeric_limits<double>::max();
            for (int o = 0; o < kk; ++o) {
                if (o != c) gap = std::min(gap, (centres[c] - centres[o]).norm());
            }
            half_gap[c] = 0.5 * gap;
        }
        for (size_t i = 0; i < n; ++i) {
            const double bound = std::max(half_gap[assignment[i]], lower[i]);
            if (upper[i] <= bound) continue;
            upper[i] = (points[i] - centres[assignment[i]]).norm();
            if (upper[i] <= bound) continue;
            nearest_two(i);
        }
    }
    return assignment;
}

int PartsFor(size_t n, int divisor) {
    if (divisor < 1) throw std::invalid_argument("K-means divisor must be >= 1");
    return std::max(1, static_cast<int>(n / static_cast<size_t>(divisor)));
}

}  // namespace strata::walls
