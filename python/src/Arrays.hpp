#pragma once
// numpy <-> strata: every array from Python is checked here once (shape, dtype, finite pose,
// orthonormal rotation) with a message naming the argument; arrays handed back own their data
// through a capsule, so results are never copied a second time.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "strata/core/Scan.hpp"

namespace strata::python {

namespace py = pybind11;

/// (N, 3) float32 or float64, any strides (a column slice of an (N, 4) KITTI array is read in
/// place). Non-finite points are kept: the integrator drops and counts them.
[[nodiscard]] std::vector<Eigen::Vector3d> PointsFromArray(const py::array& points,
                                                           const char* name = "points");
/// (4, 4) or (3, 4), finite, rotation orthonormal with determinant +1, last row 0 0 0 1.
[[nodiscard]] Eigen::Isometry3d PoseFromArray(const py::array& pose, const char* name = "pose");
/// A guess of a pose: a (4, 4) / (3, 4) pose as PoseFromArray, or (x, y, z, yaw_deg) finite.
[[nodiscard]] Eigen::Isometry3d GuessFromArray(const py::object& guess, const char* name);
/// (N,) non-negative integers of any integer dtype, N = `count`.
[[nodiscard]] std::vector<uint32_t> IdsFromArray(const py::array& ids, size_t count,
                                                 const char* name);
/// (N,) finite seconds, N = `count`: when each point was measured, after the
/// sweep's `time` (core::Scan::times_s; a span over 10 s is refused where the sweep is read).
[[nodiscard]] std::vector<float> TimesFromArray(const py::array& times, size_t count);

/// A scan from arrays: `labels` are SemanticKITTI ids (class | instance << 16, as .label files
/// and strata.simulate give them), `classes` strata's class ids (as queries give them); at most
/// one of the two, None for neither. `ray_origins` (R, 3) and `ray_starts` (R,), both or
/// neither: run r's rays start at ray_origins[r] (sensor frame) from point ray_starts[r] on, as
/// strata.read_bag gives them for deskewed sweeps (core::Scan::ray_origins).
[[nodiscard]] core::Scan ScanFromArrays(const py::array& points, const py::array& pose,
                                        const py::object& labels, const py::object& classes,
                                        const py::object& ray_origins = py::none(),
                                        const py::object& ray_starts = py::none());
/// The ray origins of `scan` as (R, 3) origins and (R,) first points; None, None when it has none.
[[nodiscard]] std::pair<py::object, py::object> RayOriginsToArrays(const core::Scan& scan);

/// A numpy array that takes over `values` (no copy); `shape`'s product must equal its size.
template <typename T>
[[nodiscard]] py::array_t<T> ToArray(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
    auto owned = std::make_unique<std::vector<T>>(std::move(values));
    T* data = owned->data();
    py::capsule base(owned.get(), [](void* p) { delete static_cast<std::vector<T>*>(p); });
    owned.release();
    return py::array_t<T>(std::move(shape), data, base);
}

/// (N, 3) array of points, float64.
[[nodiscard]] py::array_t<double> PointsToArray(const std::vector<Eigen::Vector3d>& points);
/// (4, 4) float64 array.
[[nodiscard]] py::array_t<double> MatrixToArray(const Eigen::Matrix4d& matrix);
/// Three floats from a sequence of length 3 (a box corner, an origin), named in errors.
[[nodiscard]] Eigen::Vector3d Vector3FromObject(const py::object& value, const char* name);

}  // namespace strata::python
