#include "strata/geometry/Clustering.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <utility>

#include "strata/core/Error.hpp"
#include "strata/core/GridTypes.hpp"

namespace strata::geometry {

namespace {

// The offsets of a voxel's neighbours within `eps_voxels` (itself included), z fastest.
std::vector<openvdb::Coord> NeighbourOffsets(double eps_voxels) {
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
    return offsets;
}

// The grid as the neighbour index: voxel -> position in `voxels` + 1 (0 = background).
openvdb::Int32Grid::Ptr IndexOf(const std::vector<openvdb::Coord>& voxels) {
    auto index = openvdb::Int32Grid::create(0);
    auto acc = index->getAccessor();
    for (size_t n = 0; n < voxels.size(); ++n) acc.setValue(voxels[n], static_cast<int32_t>(n + 1));
    return index;
}

}  // namespace

std::vector<std::vector<openvdb::Coord>> ConnectedVoxels(std::vector<openvdb::Coord> voxels,
                                                         double eps_voxels) {
    if (!(eps_voxels >= 1.0)) throw InvalidArgumentError("components: eps must be >= 1 voxel");
    std::sort(voxels.begin(), voxels.end());
    voxels.erase(std::unique(voxels.begin(), voxels.end()), voxels.end());
    const openvdb::Int32Grid::Ptr index = IndexOf(voxels);
    const auto acc = index->getConstAccessor();
    const std::vector<openvdb::Coord> offsets = NeighbourOffsets(eps_voxels);
    std::vector<bool> seen(voxels.size(), false);
    std::vector<std::vector<openvdb::Coord>> components;
    std::vector<int32_t> frontier;
    for (size_t seed = 0; seed < voxels.size(); ++seed) {
        if (seen[seed]) continue;
        seen[seed] = true;
        std::vector<openvdb::Coord> component;
        frontier.assign(1, static_cast<int32_t>(seed));
        while (!frontier.empty()) {
            const openvdb::Coord c = voxels[frontier.back()];
            frontier.pop_back();
            component.push_back(c);
            for (const openvdb::Coord& o : offsets) {
                const int32_t n = acc.getValue(c + o) - 1;
                if (n >= 0 && !seen[n]) {
                    seen[n] = true;
                    frontier.push_back(n);
                }
            }
        }
        std::sort(component.begin(), component.end());
        components.push_back(std::move(component));
    }
    return components;
}

std::vector<int> Dbscan(const std::vector<openvdb::Coord>& voxels, double eps_voxels,
                        int min_points) {
    if (!(eps_voxels >= 1.0)) throw InvalidArgumentError("DBSCAN: eps must be >= 1 voxel");
    if (min_points < 1) throw InvalidArgumentError("DBSCAN: min_points must be >= 1");
    const openvdb::Int32Grid::Ptr index = IndexOf(voxels);
    const std::vector<openvdb::Coord> offsets = NeighbourOffsets(eps_voxels);
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

namespace {

// k-means++: each next centre drawn with probability proportional to the squared distance to the
// nearest centre chosen so far. Fewer than k centres when there are fewer distinct points.
std::vector<Eigen::Vector3d> SeedCentres(const std::vector<Eigen::Vector3d>& points, int k,
                                         std::mt19937_64& rng) {
    const size_t n = points.size();
    std::vector<Eigen::Vector3d> centres;
    centres.push_back(points[std::uniform_int_distribution<size_t>(0, n - 1)(rng)]);
    std::vector<double> d2(n, std::numeric_limits<double>::max());
    while (static_cast<int>(centres.size()) < k) {
        double total = 0.0;
        for (size_t i = 0; i < n; ++i) {
            d2[i] = std::min(d2[i], (points[i] - centres.back()).squaredNorm());
            total += d2[i];
        }
        if (total <= 0.0) break;
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
    return centres;
}

// Lloyd's iterations with Hamerly's bounds (2010): the same assignments as plain Lloyd, but a
// point is only compared with every centre when its distance bounds cannot rule a change out.
// upper[i] bounds the distance to its centre from above, lower[i] the distance to any other
// centre from below.
class HamerlyLloyd {
public:
    HamerlyLloyd(const std::vector<Eigen::Vector3d>& points, std::vector<Eigen::Vector3d> centres,
                 std::vector<int>& assignment)
        : points_(points),
          centres_(std::move(centres)),
          assignment_(assignment),
          upper_(points.size()),
          lower_(points.size()),
          moved_(centres_.size()) {
        for (size_t i = 0; i < points_.size(); ++i) AssignNearest(i);
    }

    /// One iteration; false once no centre moves (then no point would change either).
    bool Step() {
        const auto [most, second, most_moved] = MoveCentres();
        if (most == 0.0) return false;
        for (size_t i = 0; i < points_.size(); ++i) {
            upper_[i] += moved_[assignment_[i]];
            lower_[i] -= assignment_[i] == most_moved ? second : most;
        }
        const std::vector<double> half_gap = HalfGaps();
        for (size_t i = 0; i < points_.size(); ++i) {
            const double bound = std::max(half_gap[assignment_[i]], lower_[i]);
            if (upper_[i] <= bound) continue;
            upper_[i] = (points_[i] - centres_[assignment_[i]]).norm();
            if (upper_[i] <= bound) continue;
            AssignNearest(i);
        }
        return true;
    }

private:
    struct Movement {
        double most = 0.0, second = 0.0;
        int most_moved = -1;
    };

    void AssignNearest(size_t i) {
        double d1 = std::numeric_limits<double>::max(), d2nd = d1;
        int best = 0;
        for (int c = 0; c < static_cast<int>(centres_.size()); ++c) {
            const double d = (points_[i] - centres_[c]).norm();
            if (d < d1) {
                d2nd = d1;
                d1 = d;
                best = c;
            } else if (d < d2nd) {
                d2nd = d;
            }
        }
        assignment_[i] = best;
        upper_[i] = d1;
        lower_[i] = d2nd;
    }

    // Moves each centre to the mean of its points; the largest and second largest move.
    Movement MoveCentres() {
        const size_t k = centres_.size();
        std::vector<Eigen::Vector3d> sums(k, Eigen::Vector3d::Zero());
        std::vector<size_t> counts(k, 0);
        for (size_t i = 0; i < points_.size(); ++i) {
            sums[assignment_[i]] += points_[i];
            ++counts[assignment_[i]];
        }
        Movement m;
        for (size_t c = 0; c < k; ++c) {
            const Eigen::Vector3d next =
                counts[c] > 0 ? Eigen::Vector3d(sums[c] / static_cast<double>(counts[c]))
                              : centres_[c];
            moved_[c] = (next - centres_[c]).norm();
            centres_[c] = next;
            if (moved_[c] > m.most) {
                m.second = m.most;
                m.most = moved_[c];
                m.most_moved = static_cast<int>(c);
            } else if (moved_[c] > m.second) {
                m.second = moved_[c];
            }
        }
        return m;
    }

    // Half the distance from each centre to its nearest other centre.
    std::vector<double> HalfGaps() const {
        std::vector<double> half_gap(centres_.size());
        for (size_t c = 0; c < centres_.size(); ++c) {
            double gap = std::numeric_limits<double>::max();
            for (size_t o = 0; o < centres_.size(); ++o) {
                if (o != c) gap = std::min(gap, (centres_[c] - centres_[o]).norm());
            }
            half_gap[c] = 0.5 * gap;
        }
        return half_gap;
    }

    const std::vector<Eigen::Vector3d>& points_;
    std::vector<Eigen::Vector3d> centres_;
    std::vector<int>& assignment_;
    std::vector<double> upper_, lower_, moved_;
};

}  // namespace

std::vector<int> KMeans(const std::vector<Eigen::Vector3d>& points, int k, uint64_t seed,
                        int max_iterations) {
    const size_t n = points.size();
    std::vector<int> assignment(n, 0);
    if (n == 0) return assignment;
    k = std::clamp(k, 1, static_cast<int>(n));
    if (k == 1) return assignment;
    std::mt19937_64 rng(seed);
    HamerlyLloyd lloyd(points, SeedCentres(points, k, rng), assignment);
    for (int iteration = 0; iteration < max_iterations && lloyd.Step(); ++iteration) {
    }
    return assignment;
}

}  // namespace strata::geometry
