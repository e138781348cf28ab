#include "Arrays.hpp"

#include <cmath>

#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/registration/Register.hpp"

namespace strata::python {

namespace {

std::string ShapeText(const py::array& a) {
    std::string text = "(";
    for (py::ssize_t d = 0; d < a.ndim(); ++d) {
        text += (d ? ", " : "") + std::to_string(a.shape(d));
    }
    return text + (a.ndim() == 1 ? ",)" : ")");
}

std::string DtypeText(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

template <typename T>
void CopyPoints(const py::array& a, std::vector<Eigen::Vector3d>& out) {
    const auto view = a.unchecked<T, 2>();
    for (py::ssize_t i = 0; i < view.shape(0); ++i) {
        out.emplace_back(view(i, 0), view(i, 1), view(i, 2));
    }
}

}  // namespace

std::vector<Eigen::Vector3d> PointsFromArray(const py::array& points, const char* name) {
    if (points.ndim() != 2 || points.shape(1) != 3) {
        throw InvalidArgumentError(std::string(name) + " must have shape (N, 3); got " +
                                   ShapeText(points));
    }
    std::vector<Eigen::Vector3d> out;
    out.reserve(static_cast<size_t>(points.shape(0)));
    if (py::isinstance<py::array_t<float>>(points)) {
        CopyPoints<float>(points, out);
    } else if (py::isinstance<py::array_t<double>>(points)) {
        CopyPoints<double>(points, out);
    } else {
        throw InvalidArgumentError(std::string(name) + " must be float32 or float64; got " +
                                   DtypeText(points));
    }
    return out;
}

Eigen::Isometry3d PoseFromArray(const py::array& pose, const char* name) {
    const std::string what(name);
    if (pose.ndim() != 2 || pose.shape(1) != 4 || (pose.shape(0) != 4 && pose.shape(0) != 3)) {
        throw InvalidArgumentError(what + " must have shape (4, 4) or (3, 4); got " +
                                   ShapeText(pose));
    }
    if (pose.dtype().kind() != 'f' && pose.dtype().kind() != 'i' && pose.dtype().kind() != 'u') {
        throw InvalidArgumentError(what + " must be numeric; got " + DtypeText(pose));
    }
    const auto values = py::array_t<double, py::array::forcecast>(pose);  // the view's owner
    const auto m = values.unchecked<2>();
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    for (py::ssize_t r = 0; r < m.shape(0); ++r) {
        for (py::ssize_t c = 0; c < 4; ++c) T(r, c) = m(r, c);
    }
    if (!T.allFinite()) throw InvalidArgumentError(what + " has a NaN or infinite entry");
    // A pose read from a text file carries about 1e-6 of rounding; anything further off is a
    // scale or shear the integrator would silently apply to every point.
    constexpr double kOrthonormalTolerance = 1e-4;
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (error > kOrthonormalTolerance || R.determinant() < 0.0) {
        throw InvalidArgumentError(what +
                                   ": the rotation part is not orthonormal with "
                                   "determinant +1 (max |R^T R - I| = " +
                                   std::to_string(error) + ")");
    }
    if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 0.0) {
        throw InvalidArgumentError(what + ": the last row must be 0 0 0 1");
    }
    Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
    out.matrix() = T;
    return out;
}

Eigen::Isometry3d GuessFromArray(const py::object& guess, const char* name) {
    const py::array a = py::array::ensure(guess);
    if (a && a.ndim() == 1 && a.shape(0) == 4) {
        const auto values = py::array_t<double, py::array::forcecast>(a);
        const auto v = values.unchecked<1>();
        if (!std::isfinite(v(0) + v(1) + v(2) + v(3))) {
            throw InvalidArgumentError(std::string(name) + " must be finite");
        }
        return registration::PoseFromXyzYaw(v(0), v(1), v(2), v(3));
    }
    if (!a) {
        throw InvalidArgumentError(std::string(name) + " must be a 4x4 pose or (x, y, z, yaw_deg)");
    }
    return PoseFromArray(a, name);
}

std::vector<uint32_t> IdsFromArray(const py::array& ids, size_t count, const char* name) {
    const std::string what(name);
    if (ids.ndim() != 1 || static_cast<size_t>(ids.shape(0)) != count) {
        throw InvalidArgumentError(what + " must have shape (" + std::to_string(count) +
                                   ",), one per point; got " + ShapeText(ids));
    }
    if (ids.dtype().kind() != 'i' && ids.dtype().kind() != 'u') {
        throw InvalidArgumentError(what + " must be integers; got " + DtypeText(ids));
    }
    const auto values = py::array_t<int64_t, py::array::forcecast>(ids);  // the view's owner
    const auto v = values.unchecked<1>();
    std::vector<uint32_t> out(count);
    for (size_t i = 0; i < count; ++i) {
        const int64_t id = v(static_cast<py::ssize_t>(i));
        if (id < 0 || id > int64_t{0xFFFFFFFF}) {
            throw InvalidArgumentError(what + "[" + std::to_string(i) +
                                       "] = " + std::to_string(id) + " is not a label id");
        }
        out[i] = static_cast<uint32_t>(id);
    }
    return out;
}

std::vector<float> TimesFromArray(const py::array& times, size_t count) {
    if (times.ndim() != 1 || static_cast<size_t>(times.shape(0)) != count) {
        throw InvalidArgumentError("times must have shape (" + std::to_string(count) +
                                   ",), one per point; got " + ShapeText(times));
    }
    const auto values = py::array_t<double, py::array::forcecast>(times);  // the view's owner
    const auto v = values.unchecked<1>();
    std::vector<float> out(count);
    for (size_t i = 0; i < count; ++i) {
        const double t = v(static_cast<py::ssize_t>(i));
        if (!std::isfinite(t)) {
            throw InvalidArgumentError("times[" + std::to_string(i) + "] is not finite");
        }
        out[i] = static_cast<float>(t);
    }
    return out;
}

core::Scan ScanFromArrays(const py::array& points, const py::array& pose, const py::object& labels,
                          const py::object& classes, const py::object& ray_origins,
                          const py::object& ray_starts) {
    core::Scan scan;
    scan.points = PointsFromArray(points);
    scan.T_world_sensor = PoseFromArray(pose);
    scan.source = "numpy";
    if (!labels.is_none() && !classes.is_none()) {
        throw InvalidArgumentError("give labels (SemanticKITTI ids) or classes, not both");
    }
    if (!labels.is_none()) {
        // As io::ReadKittiScan does with a .label file: class in the low 16 bits, instance above.
        const core::LabelMapping mapping = core::LabelMapping::SemanticKitti();
        const std::vector<uint32_t> raw =
            IdsFromArray(py::array::ensure(labels), scan.points.size(), "labels");
        scan.labels.reserve(raw.size());
        scan.instances.reserve(raw.size());
        for (uint32_t id : raw) {
            scan.labels.push_back(mapping.Map(id & 0xFFFFu));
            scan.instances.push_back(static_cast<uint16_t>(id >> 16));
        }
    } else if (!classes.is_none()) {
        const std::vector<uint32_t> ids =
            IdsFromArray(py::array::ensure(classes), scan.points.size(), "classes");
        scan.labels.reserve(ids.size());
        for (size_t i = 0; i < ids.size(); ++i) {
            if (ids[i] >= static_cast<uint32_t>(core::kNumClasses)) {
                throw InvalidArgumentError(
                    "classes[" + std::to_string(i) + "] = " + std::to_string(ids[i]) +
                    " is not a strata class (0.." + std::to_string(core::kNumClasses - 1) + ")");
            }
            scan.labels.push_back(static_cast<core::SemanticClass>(ids[i]));
        }
    }
    if (ray_origins.is_none() != ray_starts.is_none()) {
        throw InvalidArgumentError("give ray_origins and ray_starts together, or neither");
    }
    if (!ray_origins.is_none()) {
        const std::vector<Eigen::Vector3d> origins =
            PointsFromArray(py::array::ensure(ray_origins), "ray_origins");
        const std::vector<uint32_t> starts =
            IdsFromArray(py::array::ensure(ray_starts), origins.size(), "ray_starts");
        for (size_t r = 0; r < origins.size(); ++r)
            scan.ray_origins.push_back({starts[r], origins[r]});
        scan.Validate();  // the runs' order, named in the message
    }
    return scan;
}

std::pair<py::object, py::object> RayOriginsToArrays(const core::Scan& scan) {
    if (scan.ray_origins.empty()) return {py::none(), py::none()};
    std::vector<Eigen::Vector3d> origins;
    std::vector<int64_t> starts;
    for (const core::RayOrigin& r : scan.ray_origins) {
        origins.push_back(r.origin);
        starts.push_back(static_cast<int64_t>(r.begin));
    }
    const auto n = static_cast<py::ssize_t>(starts.size());
    return {PointsToArray(origins), ToArray(std::move(starts), {n})};
}

py::array_t<double> PointsToArray(const std::vector<Eigen::Vector3d>& points) {
    std::vector<double> flat(points.size() * 3);
    for (size_t i = 0; i < points.size(); ++i) {
        for (int a = 0; a < 3; ++a) flat[3 * i + static_cast<size_t>(a)] = points[i][a];
    }
    return ToArray(std::move(flat), {static_cast<py::ssize_t>(points.size()), 3});
}

py::array_t<double> MatrixToArray(const Eigen::Matrix4d& matrix) {
    std::vector<double> flat(16);
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) flat[static_cast<size_t>(4 * r + c)] = matrix(r, c);
    }
    return ToArray(std::move(flat), {4, 4});
}

Eigen::Vector3d Vector3FromObject(const py::object& value, const char* name) {
    const py::array a = py::array::ensure(value);
    if (!a || a.ndim() != 1 || a.shape(0) != 3) {
        throw InvalidArgumentError(std::string(name) + " must be three numbers (x, y, z)");
    }
    const auto values = py::array_t<double, py::array::forcecast>(a);  // the view's owner
    const auto v = values.unchecked<1>();
    Eigen::Vector3d out(v(0), v(1), v(2));
    if (!out.allFinite()) throw InvalidArgumentError(std::string(name) + " must be finite");
    return out;
}

}  // namespace strata::python
