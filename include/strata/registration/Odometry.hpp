#pragma once
// LiDAR odometry: poses for scans that came without them, each scan registered to a local map of
// the scans before it (docs/odometry.md).

#include <Eigen/Geometry>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "strata/core/Scan.hpp"
#include "strata/registration/Gravity.hpp"
#include "strata/registration/Gyro.hpp"

namespace strata::registration {

/// @brief How the odometry registers scans and keeps its local map (docs/odometry.md, "Method").
struct OdometryConfig {
    /// Cell of the local map, metres. A scan joins the map thinned to one point per half cell and
    /// is registered thinned to one per 1.5 cells.
    double voxel_m = 1.0;
    /// Points a map cell keeps (the first that arrive); a full cell takes no more.
    int max_points_per_voxel = 20;
    /// Returns closer than this are the vehicle itself and are dropped.
    double min_range_m = 3.0;
    /// Returns farther than this are dropped, and map cells this far from the sensor leave the
    /// local map, so its size (and a scan's cost) stays flat however long the drive.
    double max_range_m = 100.0;
    /// The motion model's deviation before it has samples; points are matched within three
    /// deviations and at most one cell.
    double initial_threshold_m = 2.0;
    /// Deviations of a scan from the motion model's prediction below this do not adapt the
    /// correspondence distance (a vehicle standing still).
    double min_motion_m = 0.1;
    /// Gauss-Newton iterations per scan, and the update (metres plus radians) that ends them.
    int max_iterations = 50;
    double convergence = 1e-4;
    /// A scan with fewer matched points than this, or a smaller share of its points matched, is
    /// refused (too little overlap with the map).
    int min_correspondences = 100;
    double min_overlap = 0.2;
    /// The map around a cell (its points and its 26 neighbours') is a line when the middle
    /// eigenvalue of their covariance is below this share of the largest, else a plane when the
    /// smallest is below this share of the middle one. A scan's point whose nearest map point
    /// lies in a plane's cell is matched to that plane, in an upright line's to that line (the
    /// distance across either); other points are not matched.
    double max_planarity_ratio = 0.1;
    /// The world's z is up: the first scan is turned level by its ground plane (LevelFromGround)
    /// when the odometry is not told where the first scan is. Without ground the world is the
    /// first scan's frame, and the first step says why.
    bool level_from_ground = true;
    GroundConfig ground;

    /// @brief Throws InvalidArgumentError naming the field when a value is out of range.
    void Validate() const;
};

/// @brief What registering one scan found.
struct OdometryStep {
    Eigen::Isometry3d T_world_sensor = Eigen::Isometry3d::Identity();
    /// False when the scan was refused; `failure` says why and `T_world_sensor` is the motion
    /// model's prediction.
    bool registered = false;
    std::string failure;
    size_t points = 0;           ///< registered (thinned) points
    size_t correspondences = 0;  ///< of those, matched at the end
    double rmse_m = 0.0;         ///< of the matched residuals
    double threshold_m = 0.0;    ///< the correspondence distance used
    int iterations = 0;  ///< Gauss-Newton iterations (both passes of a sweep deskewed twice)
    /// The smallest eigenvalue of the last step's normal equations per unit of match weight
    /// (rotations scaled to metres at the points' distance): near zero along a direction the
    /// geometry does not constrain, which then keeps the prediction.
    double min_eigenvalue = 0.0;
    /// Set for a registered scan whose matches left a motion unconstrained (min_eigenvalue below
    /// 0.002: a corridor, a tunnel, an open field), where the prediction stood: which motion, in
    /// the sensor's frame, in words.
    std::string degenerate;
    /// The first scan's ground plane, when it levelled the world (or failed to).
    std::optional<GroundLevel> ground;
    /// The prediction's rotation (and the first deskewing's) came from the gyro
    /// (Odometry::PredictRotationBy), not from the motion model.
    bool gyro = false;
};

/// @brief Scan-to-map odometry with a constant-velocity prediction (its rotation from a gyro when
/// given one), an adaptive correspondence distance and a robust kernel. The world is where
/// `T_world_first` puts the first scan, else the first scan's frame turned level
/// (OdometryConfig::level_from_ground).
class Odometry {
public:
    explicit Odometry(const OdometryConfig& config = {},
                      std::optional<Eigen::Isometry3d> T_world_first = std::nullopt);
    ~Odometry();
    Odometry(Odometry&&) noexcept;
    Odometry& operator=(Odometry&&) noexcept;

    /// @brief Registers the next scan (points in the sensor frame, metres), the scans taken at a
    /// steady rate. A registered scan joins the map and the motion model; a refused one changes
    /// neither (the caller skips it or stops). Never throws for a scan it cannot register.
    OdometryStep Register(const std::vector<Eigen::Vector3d>& points);
    /// @brief The same for a scan taken at `scan.time_s`: the prediction runs at the velocity of
    /// the last two poses over their instants, and a sweep with its points' times
    /// (`scan.times_s`) is deskewed by that velocity before it is registered and joins the map.
    /// The pose found is the sensor's at `scan.time_s`.
    OdometryStep Register(const core::Scan& scan);
    /// @brief The same from `guess` instead of the motion model's prediction (a session's first
    /// scan placed in an existing map, say).
    OdometryStep Register(const std::vector<Eigen::Vector3d>& points,
                          const Eigen::Isometry3d& guess);
    /// @brief From now on, a scan with an instant (`Register(const core::Scan&)`) is predicted
    /// to have turned as `gyro` measured since the last registered scan's instant, where its
    /// readings cover that span; its translation still comes from the motion model. The gyro's
    /// bias is not estimated: the registration corrects what it adds (0.3 deg/s, 0.03 deg a
    /// sweep at 10 Hz). A sweep with its points' times is first deskewed by that prediction.
    void PredictRotationBy(Gyro gyro);
    /// @brief Adds points (world frame) to the local map without a pose: an existing map's
    /// surface around a session in it. Their cells take no points of the scans (a scan's points
    /// already there are dropped): the scans register to the map's surface where it has one and
    /// extend the local map where it has none. They leave the local map out of range as the
    /// scans' points do.
    void AddToMap(const std::vector<Eigen::Vector3d>& points_world);

    /// @brief The poses of the registered scans, in order.
    [[nodiscard]] const std::vector<Eigen::Isometry3d>& poses() const;
    /// @brief Cells and points in the local map now.
    [[nodiscard]] size_t map_cells() const;
    [[nodiscard]] size_t map_points() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace strata::registration
