#include "strata/registration/FloorHeight.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "strata/core/Error.hpp"
#include "strata/registration/Surface.hpp"

namespace strata::registration {

namespace {

// The points of a storey on horizontal surfaces: one per cell (the mean), normal within
// `max_tilt_deg` of the vertical.
std::vector<Eigen::Vector3d> HorizontalPoints(const std::vector<Eigen::Vector3d>& points,
                                              const FloorHeightConfig& config) {
    SurfaceConfig surface;
    surface.level_cells_m = {config.cell_m};
    const Surface s = Surface::FromPoints(points, surface);
    std::vector<Eigen::Vector3d> out;
    if (s.empty()) return out;
    const double min_nz = std::cos(config.max_tilt_deg * EIGEN_PI / 180.0);
    const SurfaceLevel& level = s.levels.back();
    for (size_t i = 0; i < level.points.size(); ++i) {
        if (std::abs(level.normals[i].z()) >= min_nz) out.push_back(level.points[i]);
    }
    return out;
}

// The height in [lo, hi] holding most of `points` (bins of `bin_m`), refined to the mean of the
// points within `bin_m` of the bin's centre; NaN when no point lies in [lo, hi].
double DominantHeight(const std::vector<Eigen::Vector3d>& points, double lo, double hi,
                      double bin_m) {
    const int bins = std::max(1, static_cast<int>(std::ceil((hi - lo) / bin_m)));
    std::vector<int> count(static_cast<size_t>(bins), 0);
    for (const Eigen::Vector3d& p : points) {
        if (p.z() < lo || p.z() >= hi) continue;
        ++count[static_cast<size_t>(std::min(bins - 1, static_cast<int>((p.z() - lo) / bin_m)))];
    }
    const auto best = std::max_element(count.begin(), count.end());
    if (*best == 0) return std::nan("");
    const double centre = lo + (static_cast<double>(best - count.begin()) + 0.5) * bin_m;
    double sum = 0.0;
    int n = 0;
    for (const Eigen::Vector3d& p : points) {
        if (std::abs(p.z() - centre) <= bin_m) {
            sum += p.z();
            ++n;
        }
    }
    return sum / n;
}

void DropNear(std::vector<Eigen::Vector3d>& points, double z, double band_m) {
    if (std::isnan(z)) return;
    points.erase(
        std::remove_if(points.begin(), points.end(),
                       [&](const Eigen::Vector3d& p) { return std::abs(p.z() - z) <= band_m; }),
        points.end());
}

// Heights of the reference's horizontal points per xy cell.
class ColumnIndex {
public:
    ColumnIndex(const std::vector<Eigen::Vector3d>& points, double cell_m)
        : inv_cell_(1.0 / cell_m) {
        for (const Eigen::Vector3d& p : points)
            columns_[Key(Cell(p.x()), Cell(p.y()))].push_back(p.z());
    }
    // Calls f(z) for every reference height in the 3 x 3 columns around (x, y).
    template <typename F>
    void ForNeighbours(const Eigen::Vector3d& p, F&& f) const {
        const int64_t cx = Cell(p.x()), cy = Cell(p.y());
        for (int64_t dx = -1; dx <= 1; ++dx) {
            for (int64_t dy = -1; dy <= 1; ++dy) {
                const auto it = columns_.find(Key(cx + dx, cy + dy));
                if (it == columns_.end()) continue;
                for (double z : it->second) f(z);
            }
        }
    }

private:
    [[nodiscard]] int64_t Cell(double v) const {
        return static_cast<int64_t>(std::floor(v * inv_cell_));
    }
    // Unsigned: shifting a negative signed value is undefined (UBSan caught it).
    [[nodiscard]] static uint64_t Key(int64_t x, int64_t y) {
        return (static_cast<uint64_t>(x) << 32) ^ (static_cast<uint64_t>(y) & 0xffffffffU);
    }
    double inv_cell_;
    std::unordered_map<uint64_t, std::vector<double>> columns_;
};

// Matched points and the mean vertical residual at offset `dz`: each floor point's nearest
// reference height in its columns, when within `max_r`.
struct Fit {
    int matches = 0;
    double sum_w = 0.0, sum_wr = 0.0, sum_r2 = 0.0;
};
Fit FitAt(const ColumnIndex& index, const std::vector<Eigen::Vector3d>& floor, double dz,
          double max_r, double cauchy_m) {
    Fit fit;
    for (const Eigen::Vector3d& p : floor) {
        double best = max_r;
        bool found = false;
        index.ForNeighbours(p, [&](double z) {
            const double r = z - (p.z() + dz);
            if (std::abs(r) < std::abs(best)) {
                best = r;
                found = true;
            }
        });
        if (!found) continue;
        // Cauchy weights (IRLS): a wrong match near the limit counts little.
        const double w = 1.0 / (1.0 + (best / cauchy_m) * (best / cauchy_m));
        ++fit.matches;
        fit.sum_w += w;
        fit.sum_wr += w * best;
        fit.sum_r2 += best * best;
    }
    return fit;
}

}  // namespace

void FloorHeightConfig::Validate() const {
    auto require = [](bool ok, const char* what) {
        if (!ok) throw InvalidArgumentError(std::string("floor height config: ") + what);
    };
    require(std::isfinite(search_m) && search_m > 0.0, "search_m must be positive");
    require(std::isfinite(cell_m) && cell_m > 0.0, "cell_m must be positive");
    require(max_tilt_deg > 0.0 && max_tilt_deg < 90.0, "max_tilt_deg must be in (0, 90)");
    require(slab_band_m >= 0.0 && slab_band_m < search_m, "slab_band_m must be in [0, search_m)");
    require(inlier_m > 0.0 && inlier_m < search_m, "inlier_m must be in (0, search_m)");
    require(min_matches >= 1, "min_matches must be >= 1");
    require(max_second_ratio > 0.0 && max_second_ratio <= 1.0,
            "max_second_ratio must be in (0, 1]");
}

FloorHeightResult MeasureFloorHeight(const std::vector<Eigen::Vector3d>& reference_map,
                                     double reference_floor_z_m,
                                     const std::vector<Eigen::Vector3d>& floor_points,
                                     const Eigen::Isometry3d& T_map_floor,
                                     const FloorHeightConfig& config) {
    config.Validate();
    FloorHeightResult out;
    const double z_guess = T_map_floor.translation().z();
    out.z_m = z_guess;
    // Step 1: horizontal points of both storeys, the floor's moved to the map by the guess.
    std::vector<Eigen::Vector3d> reference = HorizontalPoints(reference_map, config);
    std::vector<Eigen::Vector3d> floor_local = HorizontalPoints(floor_points, config);
    // Step 2: the slab between them. The floor below sees its ceiling (upper half of its storey,
    // up to the guess), the floor sees its own surface (near its z = 0); no storey sees both
    // faces, so they would pull z by the slab's thickness. Both are dropped.
    const double bin = 2.0 * config.inlier_m;
    out.ceiling_below_z_m = DominantHeight(reference, 0.5 * (reference_floor_z_m + z_guess),
                                           z_guess + config.search_m, bin);
    out.floor_surface_z_m = DominantHeight(floor_local, -config.search_m, config.search_m, bin);
    DropNear(reference, out.ceiling_below_z_m, config.slab_band_m);
    DropNear(floor_local, out.floor_surface_z_m, config.slab_band_m);
    std::vector<Eigen::Vector3d> floor;
    floor.reserve(floor_local.size());
    for (const Eigen::Vector3d& p : floor_local) floor.push_back(T_map_floor * p);
    out.reference_horizontal = reference.size();
    out.floor_horizontal = floor.size();

    // Step 3: a 1-D vote over the offset: every floor point votes (once per bin) for the
    // offsets within inlier_m of a reference height in its columns.
    const ColumnIndex index(reference, config.cell_m);
    const double step = 0.25 * config.inlier_m;
    const int half = static_cast<int>(std::ceil(config.search_m / step));
    std::vector<int> votes(static_cast<size_t>(2 * half + 1), 0);
    std::vector<int> last_voter(votes.size(), -1);
    for (size_t i = 0; i < floor.size(); ++i) {
        const Eigen::Vector3d& p = floor[i];
        index.ForNeighbours(p, [&](double z) {
            const double d = z - p.z();
            const int lo =
                std::max(-half, static_cast<int>(std::ceil((d - config.inlier_m) / step)));
            const int hi =
                std::min(half, static_cast<int>(std::floor((d + config.inlier_m) / step)));
            for (int b = lo; b <= hi; ++b) {
                const size_t k = static_cast<size_t>(b + half);
                if (last_voter[k] == static_cast<int>(i)) continue;
                last_voter[k] = static_cast<int>(i);
                ++votes[k];
            }
        });
    }
    // The best offset (ties: nearest the z-bias) and the best one outside its peak.
    size_t best = static_cast<size_t>(half);
    for (size_t k = 0; k < votes.size(); ++k) {
        const bool nearer =
            std::abs(static_cast<int>(k) - half) < std::abs(static_cast<int>(best) - half);
        if (votes[k] > votes[best] || (votes[k] == votes[best] && nearer)) best = k;
    }
    const double dz0 = (static_cast<int>(best) - half) * step;
    for (size_t k = 0; k < votes.size(); ++k) {
        const double d = (static_cast<int>(k) - half) * step;
        if (std::abs(d - dz0) > 2.0 * config.inlier_m) {
            out.second_matches = std::max(out.second_matches, votes[k]);
        }
    }
    out.matches = votes[best];
    if (out.matches < config.min_matches) {
        out.refusal = "z not measured: " + std::to_string(out.matches) +
                      " points on horizontal surfaces shared with the floor below (need " +
                      std::to_string(config.min_matches) +
                      "); the storeys saw no common steps, landings or shaft bottom";
        return out;
    }
    if (out.second_matches >= config.max_second_ratio * out.matches) {
        out.refusal = "z not measured: ambiguous, " + std::to_string(out.second_matches) +
                      " points fit another height as well as " + std::to_string(out.matches) +
                      " fit the best";
        return out;
    }
    // Step 4: robust least squares (IRLS, Cauchy) of the 1-D offset from the vote's peak.
    double dz = dz0;
    Fit fit;
    for (int it = 0; it < 10; ++it) {
        fit = FitAt(index, floor, dz, config.inlier_m, 0.5 * config.inlier_m);
        if (fit.sum_w <= 0.0) break;
        const double step_m = fit.sum_wr / fit.sum_w;
        dz += step_m;
        if (std::abs(step_m) < 1e-5) break;
    }
    fit = FitAt(index, floor, dz, config.inlier_m, 0.5 * config.inlier_m);
    out.matches = fit.matches;
    out.rmse_m = fit.matches > 0 ? std::sqrt(fit.sum_r2 / fit.matches) : 0.0;
    out.dz_m = dz;
    out.z_m = z_guess + dz;
    out.measured = out.matches >= config.min_matches;
    if (!out.measured) {
        out.refusal = "z not measured: the fit kept " + std::to_string(out.matches) + " points";
    }
    return out;
}

}  // namespace strata::registration
