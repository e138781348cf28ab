#pragma once
// Deskewing: a sweep's points, each measured from where the sensor was at its own instant, moved
// into the sensor's frame at the sweep's stamp (docs/recordings.md, "Deskewing"). The motion comes
// from a recording's tf tree or from the odometry's trajectory.

#include <Eigen/Geometry>
#include <functional>
#include <vector>

#include "strata/core/Scan.hpp"

namespace strata::recordings {

/// @brief Where the sensor was `tau` seconds after a sweep's stamp, in its frame at the stamp.
using SweepMotion = std::function<Eigen::Isometry3d(double tau)>;

/// @brief Throws FormatError naming `scan.source` when its points' times span more than 10 s (a
/// sweep takes a fraction of a second) or are not finite.
void RequireSweepTimes(const core::Scan& scan);

/// @brief Moves each point of `scan` (in the sensor's frame of its instant, `scan.times_s` after
/// the stamp) into the sensor's frame at the stamp, by `motion` sampled every millisecond across
/// the sweep and interpolated between. The points (with their intensities, labels and instances)
/// are then ordered into runs over which the sensor moved at most 5 cm, each with the ray origin
/// of the run's middle (`scan.ray_origins`, within 2.5 cm of each point's own), and `times_s`
/// is emptied. A scan without times is left as it is.
/// @throw RequireSweepTimes's; whatever `motion` throws (a time outside a known trajectory).
void Deskew(core::Scan& scan, const SweepMotion& motion);

/// @brief Deskew with the motion of a trajectory (`poses` at increasing instants `times_s`, the
/// odometry's), interpolated between its poses and extrapolated past its ends, relative to
/// `scan.T_world_sensor`, the sweep's pose at its stamp (`scan.time_s`) on that trajectory.
void DeskewAlong(core::Scan& scan, const std::vector<double>& times_s,
                 const std::vector<Eigen::Isometry3d>& poses);

}  // namespace strata::recordings
