// strata.read_points, strata.read_kitti and strata.read_bag: the io readers and a recording's
// sweeps, arrays out.
#include <filesystem>

#include "Arrays.hpp"
#include "Bindings.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PointCloudReaders.hpp"
#include "strata/recordings/RecordedScans.hpp"

namespace strata::python {

namespace {

// The readers report a missing file as a generic failure; Python callers expect LookupError.
void RequireExists(const std::string& path) {
    if (!std::filesystem::exists(path)) throw NotFoundError(path + ": no such file or folder");
}

/// A scan's per-point data as a dict of arrays (None where the file had none).
py::dict ScanToDict(core::Scan&& scan) {
    py::dict out;
    out["points"] = PointsToArray(scan.points);
    const auto n = static_cast<py::ssize_t>(scan.points.size());
    if (scan.has_labels()) {
        std::vector<uint8_t> classes(scan.labels.size());
        for (size_t i = 0; i < classes.size(); ++i)
            classes[i] = static_cast<uint8_t>(scan.labels[i]);
        out["classes"] = ToArray(std::move(classes), {n});
    } else {
        out["classes"] = py::none();
    }
    out["instances"] = scan.instances.empty() ? py::object(py::none())
                                              : py::object(ToArray(std::move(scan.instances), {n}));
    out["intensity"] = scan.intensity.empty() ? py::object(py::none())
                                              : py::object(ToArray(std::move(scan.intensity), {n}));
    out["pose"] = MatrixToArray(scan.T_world_sensor.matrix());
    auto [origins, starts] = RayOriginsToArrays(scan);
    out["ray_origins"] = std::move(origins);
    out["ray_starts"] = std::move(starts);
    out["time"] = scan.time_s;
    // Seconds after `time` at which each point was measured: a recording's sweep read unposed.
    out["times"] = scan.times_s.empty() ? py::object(py::none())
                                        : py::object(ToArray(std::move(scan.times_s), {n}));
    return out;
}

py::dict ReadPoints(const std::string& path, int bin_fields, const py::object& origin) {
    io::ReadOptions options;
    options.bin_fields = bin_fields;
    if (!origin.is_none()) options.origin = Vector3FromObject(origin, "origin");
    RequireExists(path);
    core::Scan scan;
    {
        py::gil_scoped_release release;
        scan = io::ReadPointCloud(path, options);
    }
    return ScanToDict(std::move(scan));
}

py::dict ReadKitti(const std::string& dir) {
    RequireExists(dir);
    io::KittiSequence seq;
    {
        py::gil_scoped_release release;
        seq = io::OpenKittiSequence(dir);
    }
    py::list scans, labels;
    for (const auto& f : seq.scan_files) scans.append(f.string());
    for (const auto& f : seq.label_files) labels.append(f.string());
    std::vector<double> poses;
    poses.reserve(seq.size() * 16);
    for (const Eigen::Isometry3d& T : seq.T_world_sensor) {
        for (int r = 0; r < 4; ++r) {
            for (int c = 0; c < 4; ++c) poses.push_back(T.matrix()(r, c));
        }
    }
    py::dict out;
    const auto n = static_cast<py::ssize_t>(seq.size());
    out["scans"] = scans;
    out["labels"] = labels;
    out["poses"] = ToArray(std::move(poses), {n, 4, 4});
    out["times"] = ToArray(std::vector<double>(seq.times_s), {n});
    return out;
}

}  // namespace

void RegisterReaders(py::module_& m) {
    m.def("_read_points", &ReadPoints, py::arg("path"), py::arg("bin_fields") = 0,
          py::arg("origin") = py::none());
    m.def("_read_kitti", &ReadKitti, py::arg("dir"));
    // A recording's sweeps, one at a time (strata.read_bag wraps it in a generator).
    using recordings::RecordedScans;
    py::class_<RecordedScans>(m, "_Recording")
        .def(py::init([](const std::string& path, const std::string& points_topic,
                         const std::string& fixed_frame, const std::string& odom_topic, bool deskew,
                         const std::string& frames, bool posed) {
                 RequireExists(path);
                 recordings::RecordedScanOptions options;
                 options.points_topic = points_topic;
                 options.fixed_frame = fixed_frame;
                 options.odom_topic = odom_topic;
                 options.deskew = deskew;
                 options.frames = frames;
                 options.posed = posed;
                 options.imu = false;  // the gyro's prediction is strata odometry's (not here)
                 py::gil_scoped_release release;
                 return RecordedScans::Open(path, options);
             }),
             py::arg("path"), py::arg("points_topic"), py::arg("fixed_frame"),
             py::arg("odom_topic"), py::arg("deskew"), py::arg("frames"), py::arg("posed"))
        .def("__len__", &RecordedScans::size)
        .def("scan",
             [](const RecordedScans& scans, size_t k) {
                 if (k >= scans.size()) throw py::index_error("no sweep " + std::to_string(k));
                 core::Scan scan;
                 {
                     py::gil_scoped_release release;
                     scan = scans.Read(k);
                 }
                 return ScanToDict(std::move(scan));
             })
        .def_property_readonly("points_topic", &RecordedScans::points_topic)
        .def_property_readonly("fixed_frame", &RecordedScans::fixed_frame)
        .def_property_readonly("deskew_note", &RecordedScans::deskew_note);
}

}  // namespace strata::python
