#include "strata/io/PoseFiles.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>

#include "TextParsing.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/AtomicFile.hpp"

namespace strata::io {
namespace {

// KITTI writes 7 significant digits, so a valid rotation is orthonormal to about 1e-6.
constexpr double kRotationTolerance = 1e-3;

[[noreturn]] void Fail(const std::string& file, size_t line, const std::string& message) {
    throw FormatError(file + ": line " + std::to_string(line) + ": " + message);
}

// Parses every field of a data line as a finite number.
std::vector<double> ParseNumbers(const std::vector<std::string_view>& fields,
                                 const std::string& file, size_t line) {
    std::vector<double> values(fields.size());
    for (size_t i = 0; i < fields.size(); ++i) {
        if (!detail::ParseDouble(fields[i], values[i])) {
            Fail(file, line, "cannot parse '" + std::string(fields[i].substr(0, 40)) + "'");
        }
        if (!std::isfinite(values[i]))
            Fail(file, line, "value " + std::to_string(i + 1) + " is not finite");
    }
    return values;
}

// Row-major 3x4 [R|t] from values[first .. first + 11], with R checked to be a rotation.
Eigen::Isometry3d PoseFrom3x4(const std::vector<double>& values, size_t first,
                              const std::string& file, size_t line) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c)
            T.matrix()(r, c) = values[first + static_cast<size_t>(4 * r + c)];
    }
    const Eigen::Matrix3d R = T.linear();
    if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() >
            kRotationTolerance ||
        R.determinant() < 0.0) {
        Fail(file, line, "the 3x3 block is not a rotation");
    }
    return T;
}

// Calls visit(fields, line_number) for every line that has data after comments are removed.
template <typename Visit>
void ForEachDataLine(const std::string& text, Visit visit) {
    detail::LineReader lines(text);
    std::vector<std::string_view> fields;
    std::string_view line;
    while (lines.Next(line)) {
        detail::SplitFields(detail::StripComment(line), fields);
        if (!fields.empty()) visit(fields, lines.line_number());
    }
}

std::vector<StampedPose> ParseKitti(const std::string& text, const std::string& file) {
    std::vector<StampedPose> poses;
    ForEachDataLine(text, [&](const std::vector<std::string_view>& fields, size_t line) {
        if (fields.size() != 12) {
            Fail(file, line,
                 "expected 12 values (KITTI 3x4 pose), found " + std::to_string(fields.size()));
        }
        const std::vector<double> v = ParseNumbers(fields, file, line);
        poses.push_back({std::numeric_limits<double>::quiet_NaN(), PoseFrom3x4(v, 0, file, line)});
    });
    return poses;
}

std::vector<StampedPose> ParseTum(const std::string& text, const std::string& file) {
    std::vector<StampedPose> poses;
    ForEachDataLine(text, [&](const std::vector<std::string_view>& fields, size_t line) {
        if (fields.size() != 8) {
            Fail(file, line,
                 "expected 8 values (TUM: t x y z qx qy qz qw), found " +
                     std::to_string(fields.size()));
        }
        const std::vector<double> v = ParseNumbers(fields, file, line);
        Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
        if (q.norm() < 1e-9) Fail(file, line, "the quaternion is zero");
        StampedPose pose;
        pose.time_s = v[0];
        pose.T.linear() = q.normalized().toRotationMatrix();
        pose.T.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
        poses.push_back(pose);
    });
    return poses;
}

}  // namespace

std::vector<Eigen::Isometry3d> ReadKittiPoses(const std::filesystem::path& path) {
    std::vector<Eigen::Isometry3d> poses;
    for (const StampedPose& p : ParseKitti(detail::ReadTextFile(path), path.string())) {
        poses.push_back(p.T);
    }
    return poses;
}

std::vector<StampedPose> ReadTumPoses(const std::filesystem::path& path) {
    return ParseTum(detail::ReadTextFile(path), path.string());
}

Eigen::Isometry3d ReadKittiCalibTr(const std::filesystem::path& calib_txt) {
    const std::string file = calib_txt.string();
    bool found = false;
    Eigen::Isometry3d Tr = Eigen::Isometry3d::Identity();
    ForEachDataLine(detail::ReadTextFile(calib_txt),
                    [&](const std::vector<std::string_view>& fields, size_t line) {
                        if (fields[0] != "Tr:") return;
                        if (fields.size() != 13) Fail(file, line, "`Tr:` needs 12 values");
                        const std::vector<std::string_view> numbers(fields.begin() + 1,
                                                                    fields.end());
                        Tr = PoseFrom3x4(ParseNumbers(numbers, file, line), 0, file, line);
                        found = true;
                    });
    if (!found) throw FormatError(file + ": no `Tr:` line (velodyne -> camera transform)");
    return Tr;
}

std::vector<StampedPose> ReadPoseFile(const std::filesystem::path& path) {
    const std::string file = path.string();
    const std::string text = detail::ReadTextFile(path);
    size_t columns = 0, first_line = 0;
    ForEachDataLine(text, [&](const std::vector<std::string_view>& fields, size_t line) {
        if (columns == 0) {
            columns = fields.size();
            first_line = line;
        }
    });
    if (columns == 12) return ParseKitti(text, file);
    if (columns == 8) return ParseTum(text, file);
    if (columns == 0) return {};
    Fail(file, first_line,
         std::to_string(columns) + " values: neither a KITTI (12) nor a TUM (8) pose line");
}

std::vector<double> ReadTimes(const std::filesystem::path& path) {
    const std::string file = path.string();
    std::vector<double> times;
    ForEachDataLine(detail::ReadTextFile(path),
                    [&](const std::vector<std::string_view>& fields, size_t line) {
                        if (fields.size() != 1) Fail(file, line, "expected one timestamp");
                        times.push_back(ParseNumbers(fields, file, line)[0]);
                    });
    return times;
}

namespace {

// Writes with full double precision, whole or not at all (WriteFileAtomically reports any
// stream failure, a full disk say, and leaves an existing file as it was).
template <typename Body>
void WriteText(const std::filesystem::path& path, Body body) {
    WriteFileAtomically(path, [&](std::ostream& out) {
        out.precision(std::numeric_limits<double>::max_digits10);
        body(out);
    });
}

}  // namespace

void WriteKittiPoses(const std::filesystem::path& path,
                     const std::vector<Eigen::Isometry3d>& poses) {
    WriteText(path, [&](std::ostream& out) {
        for (const Eigen::Isometry3d& T : poses) {
            for (int k = 0; k < 12; ++k) out << (k ? " " : "") << T.matrix()(k / 4, k % 4);
            out << '\n';
        }
    });
}

void WriteTumPoses(const std::filesystem::path& path, const std::vector<StampedPose>& poses) {
    WriteText(path, [&](std::ostream& out) {
        out << "# t x y z qx qy qz qw\n";
        for (const StampedPose& p : poses) {
            const Eigen::Quaterniond q(p.T.linear());
            const Eigen::Vector3d t = p.T.translation();
            out << p.time_s << ' ' << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x() << ' '
                << q.y() << ' ' << q.z() << ' ' << q.w() << '\n';
        }
    });
}

}  // namespace strata::io
