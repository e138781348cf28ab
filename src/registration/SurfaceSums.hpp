#pragma once
// Private to the registration module: the sums a matching surface is fitted from, cell by cell
// (docs/registration.md, step 1). Shared by Surface::FromPoints (every cell of a point set) and
// MapSurface (only the cells a source can reach, read from a map's tiles).

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

#include "strata/registration/RegistrationConfig.hpp"
#include "strata/registration/Surface.hpp"

namespace strata::registration::detail {

/// Point count, sum and sum of outer products of a cell's points, each point taken relative to
/// the cell's centre in units of cell / 2^20. Integers: the sums are the same in any order, so
/// a surface does not depend on how its points were split into tiles or threads.
struct CellSums {
    int64_t n = 0;
    std::array<int64_t, 3> s{};
    std::array<int64_t, 6> q{};  ///< xx, xy, xz, yy, yz, zz
    CellSums& operator+=(const CellSums& o);
};

/// The cell sums of one level.
class LevelSums {
public:
    /// @throw InvalidArgumentError when `cell_m` is not > 0.
    explicit LevelSums(double cell_m);

    [[nodiscard]] double cell_m() const { return cell_m_; }
    [[nodiscard]] openvdb::Coord CellOf(const Eigen::Vector3d& p) const;
    /// @brief Adds a finite point to its cell. Throws InvalidArgumentError past 2^25 points in
    /// one cell (where the sums could overflow).
    void Add(const Eigen::Vector3d& p);
    /// @brief Adds another part's sums (same cell size) and empties it, so that the parts and
    /// their sum are not all held at once. Throws as Add().
    void Merge(LevelSums&& other);
    [[nodiscard]] size_t cells() const { return sums_.size(); }

    /// @brief The level: for each cell (of `fit` when given, else every cell) the mean of its
    /// points and, when its own points or those of the 27 cells around it make a plane, its
    /// normal; cells without a plane are dropped. Cells in coordinate order (deterministic).
    [[nodiscard]] SurfaceLevel Finish(const SurfaceConfig& config,
                                      const CellMask* fit = nullptr) const;

private:
    double cell_m_;
    double inv_cell_;
    double quantum_;                            // metres per unit of the sums
    CellSums& SumsOf(const openvdb::Coord& c);  // inserted when new

    std::vector<openvdb::Coord> cells_;  // in the order they came
    std::vector<CellSums> sums_;         // of cells_[k]
    CellTable at_;                       // cell -> k
};

}  // namespace strata::registration::detail
