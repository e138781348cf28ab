#pragma once
// Private to registration: the odometry's local map, a hash of cells each holding a few points
// and the shape of the map around it (docs/odometry.md, "Method").

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace strata::registration::detail {

/// @brief The shape of the map around a cell, from its points and its 26 neighbours': a plane
/// (ground, a facade), a line (a pole, one ring of a sensor's returns on the ground) or neither.
enum class Shape : uint8_t { kPoint, kLine, kPlane };

/// @brief Where a query point found the map: the nearest map point, and the shape around its
/// cell with the plane's normal or the line's direction (`axis`).
struct MapMatch {
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    Eigen::Vector3d axis = Eigen::Vector3d::Zero();
    Shape shape = Shape::kPoint;
    double distance = 0.0;
};

class LocalMap {
public:
    LocalMap(double cell_m, int max_points_per_cell, double max_planarity_ratio);

    /// @brief Adds points (world frame) to their cells, each up to its capacity, then refits the
    /// shapes of the cells that changed. `fixed` points are a stored map's: their cells hold only
    /// such points (a scan's points there are dropped, and added later ones are refused), so a
    /// scan registers to the stored surface where there is one, not to its own earlier copies.
    void Add(const std::vector<Eigen::Vector3d>& points, bool fixed = false);
    /// @brief Drops the cells whose first point lies farther than `radius` from `centre`.
    void RemoveFarFrom(const Eigen::Vector3d& centre, double radius);
    /// @brief The nearest map point to `p` within `max_distance` (searching p's cell and the 26
    /// around it) with its cell's shape; false when there is none. Safe from many threads
    /// between changes.
    bool Nearest(const Eigen::Vector3d& p, double max_distance, MapMatch* match) const;

    [[nodiscard]] bool empty() const { return cells_.empty(); }
    [[nodiscard]] size_t cells() const { return cells_.size(); }
    [[nodiscard]] size_t points() const;

private:
    struct Key {
        int32_t x, y, z;
        bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
    };
    struct KeyHash {
        size_t operator()(const Key& k) const {
            // Three large primes, as spatial hashes commonly mix cell coordinates.
            return static_cast<size_t>(static_cast<uint32_t>(k.x) * 73856093u ^
                                       static_cast<uint32_t>(k.y) * 19349669u ^
                                       static_cast<uint32_t>(k.z) * 83492791u);
        }
    };
    struct Cell {
        std::vector<Eigen::Vector3d> points;
        Eigen::Vector3d axis = Eigen::Vector3d::Zero();
        Shape shape = Shape::kPoint;
        bool fixed = false;    // a stored map's cell (Add)
        bool changed = false;  // within one Add
    };
    [[nodiscard]] Key KeyOf(const Eigen::Vector3d& p) const;
    // Calls f(cell) for `key`'s cell and each of the 26 around it that holds points.
    template <typename F>
    void ForNeighbours(const Key& key, F&& f) const {
        for (int32_t dx = -1; dx <= 1; ++dx) {
            for (int32_t dy = -1; dy <= 1; ++dy) {
                for (int32_t dz = -1; dz <= 1; ++dz) {
                    const auto it = cells_.find({key.x + dx, key.y + dy, key.z + dz});
                    if (it != cells_.end()) f(it->second);
                }
            }
        }
    }
    void FitShape(const Key& key, Cell& cell) const;

    double cell_m_;
    size_t capacity_;
    double max_planarity_ratio_;
    std::unordered_map<Key, Cell, KeyHash> cells_;
};

}  // namespace strata::registration::detail
