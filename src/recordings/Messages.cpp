// Decoders of the map-carrying messages. One reader serves both serializations: ROS 1's
// (little-endian, unaligned, strings without a terminator, a sequence number in every header) and
// ROS 2's CDR (a 4-byte encapsulation header saying the byte order, each primitive aligned to its
// size from the end of that header, strings with a terminating NUL counted in their length).
#include "strata/recordings/Messages.hpp"

#include <cmath>
#include <limits>
#include <optional>

#include "FileReader.hpp"

namespace strata::recordings {
namespace {

using core::ByteCursor;

class MessageReader {
public:
    MessageReader(const Message& m, const std::string& file)
        : in_(m.data, m.size,
              file + ": " + m.topic->name + " message logged at " + FormatStamp(m.log_time_ns)),
          cdr_(m.topic->encoding == Encoding::kCdr) {
        if (m.topic->encoding == Encoding::kOther) {
            in_.Fail(
                "its messages are not serialized as ROS 1 or CDR: strata does not decode them");
        }
        if (cdr_) {
            const uint8_t* h = in_.Take(4, "CDR encapsulation header");
            // 0x0000 CDR_BE, 0x0001 CDR_LE; XCDR2's plain forms (0x0006, 0x0007) lay out these
            // messages' fields the same way up to 8-byte alignment, which they cap at 4.
            if (h[0] != 0 || (h[1] != 0 && h[1] != 1)) {
                in_.Fail("CDR encapsulation " + std::to_string(h[0]) + "," + std::to_string(h[1]) +
                         " is not plain CDR (strata reads CDR_LE and CDR_BE)");
            }
            big_endian_ = h[1] == 0;
            origin_ = in_.position();
        }
    }

    [[noreturn]] void Fail(const std::string& message) const { in_.Fail(message); }

    template <typename T>
    [[nodiscard]] T Read(const char* what) {
        Align(sizeof(T));
        return in_.Read<T>(what, big_endian_);
    }

    [[nodiscard]] std::string String(const char* what) {
        const auto n = Read<uint32_t>(what);
        const auto* p = reinterpret_cast<const char*>(in_.Take(n, what));
        if (!cdr_) return std::string(p, n);
        if (n == 0 || p[n - 1] != '\0') Fail(std::string(what) + ": a CDR string without its NUL");
        return std::string(p, n - 1);
    }

    /// @brief A sequence's element count, checked against the bytes left (each element takes at
    /// least `min_element_bytes`), so that a lying count fails before anything is allocated.
    [[nodiscard]] uint32_t Count(const char* what, size_t min_element_bytes) {
        const auto n = Read<uint32_t>(what);
        if (static_cast<uint64_t>(n) * min_element_bytes > in_.remaining()) {
            Fail(std::string(what) + ": " + std::to_string(n) + " elements do not fit in the " +
                 std::to_string(in_.remaining()) + " bytes left");
        }
        return n;
    }

    const uint8_t* Bytes(size_t n, const char* what) { return in_.Take(n, what); }

    [[nodiscard]] Header ReadHeader() {
        Header h;
        if (!cdr_) static_cast<void>(Read<uint32_t>("header.seq"));
        const auto sec = cdr_ ? static_cast<int64_t>(Read<int32_t>("header.stamp.sec"))
                              : static_cast<int64_t>(Read<uint32_t>("header.stamp.sec"));
        const auto nsec = Read<uint32_t>("header.stamp.nanosec");
        if (nsec >= 1000000000u) Fail("header.stamp has " + std::to_string(nsec) + " ns");
        h.stamp_ns = sec * 1000000000 + static_cast<int64_t>(nsec);
        h.frame_id = String("header.frame_id");
        return h;
    }

    [[nodiscard]] Eigen::Vector3d Vector(const char* what) {
        Eigen::Vector3d v;
        for (int i = 0; i < 3; ++i) v[i] = Read<double>(what);
        return v;
    }

    /// @brief geometry_msgs/Quaternion (x, y, z, w), normalized; refused when it is not a
    /// rotation (zero, or not finite).
    [[nodiscard]] Eigen::Quaterniond Rotation(const char* what) {
        const Eigen::Vector3d xyz = Vector(what);
        const double w = Read<double>(what);
        Eigen::Quaterniond q(w, xyz.x(), xyz.y(), xyz.z());
        const double norm = q.norm();
        if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) {
            Fail(std::string(what) + " is not a unit quaternion (norm " + std::to_string(norm) +
                 ")");
        }
        q.normalize();
        return q;
    }

    [[nodiscard]] Eigen::Isometry3d Pose(const char* what) {
        Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
        T.translation() = Vector(what);
        T.linear() = Rotation(what).toRotationMatrix();
        // Beyond a million kilometres is damage (and keeps every composed pose finite).
        if (!(T.translation().norm() < 1e9)) {
            Fail(std::string(what) + " is not finite or more than 1e9 m away");
        }
        return T;
    }

    void SkipDoubles(size_t n, const char* what) {
        for (size_t i = 0; i < n; ++i) static_cast<void>(Read<double>(what));
    }

private:
    void Align(size_t n) {
        if (!cdr_) return;
        const size_t offset = in_.position() - origin_;
        const size_t pad = (n - offset % n) % n;
        if (pad > 0) in_.Skip(pad, "CDR alignment");
    }

    ByteCursor in_;
    bool cdr_;
    bool big_endian_ = false;
    size_t origin_ = 0;
};

// Times a point may have: at most this far from its cloud's stamp (relative fields), and absolute
// ones between the epoch and 2106 (ROS 1's u32 seconds); beyond is damage, and keeps every sum of
// stamps within int64.
constexpr double kMaxPointOffsetNs = 1e12;
constexpr double kMaxStampNs = 4294967296e9;

// sensor_msgs/PointField's datatypes 1 (INT8) to 8 (FLOAT64) as core's scalar types.
std::optional<core::ScalarType> ScalarOf(uint8_t datatype) {
    using core::ScalarType;
    constexpr ScalarType kTypes[] = {ScalarType::kI8,  ScalarType::kU8,  ScalarType::kI16,
                                     ScalarType::kU16, ScalarType::kI32, ScalarType::kU32,
                                     ScalarType::kF32, ScalarType::kF64};
    if (datatype < 1 || datatype > 8) return std::nullopt;
    return kTypes[datatype - 1];
}

struct Field {
    std::string name;
    uint32_t offset = 0;
    core::ScalarType type = core::ScalarType::kU8;
};

}  // namespace

bool IsType(const Topic& topic, const std::string& ros1_type) {
    if (topic.type == ros1_type) return true;
    const size_t slash = ros1_type.find('/');
    return slash != std::string::npos &&
           topic.type == ros1_type.substr(0, slash) + "/msg" + ros1_type.substr(slash);
}

Header DecodeHeader(const Message& message, const std::string& file) {
    MessageReader in(message, file);
    return in.ReadHeader();
}

PointCloud DecodePointCloud2(const Message& message, const std::string& file) {
    MessageReader in(message, file);
    PointCloud cloud;
    cloud.header = in.ReadHeader();
    const auto height = in.Read<uint32_t>("height");
    const auto width = in.Read<uint32_t>("width");
    const uint32_t field_count = in.Count("fields", 13);  // name length, offset, type, count
    std::vector<Field> fields(field_count);
    for (Field& f : fields) {
        f.name = in.String("field name");
        f.offset = in.Read<uint32_t>("field offset");
        const auto datatype = in.Read<uint8_t>("field datatype");
        static_cast<void>(in.Read<uint32_t>("field count"));
        const std::optional<core::ScalarType> type = ScalarOf(datatype);
        if (!type) {
            in.Fail("field " + f.name + " has datatype " + std::to_string(datatype) +
                    " (sensor_msgs/PointField knows 1 to 8)");
        }
        f.type = *type;
    }
    const bool big_endian = in.Read<uint8_t>("is_bigendian") != 0;
    const auto point_step = in.Read<uint32_t>("point_step");
    const auto row_step = in.Read<uint32_t>("row_step");
    const uint32_t data_size = in.Count("data", 1);
    const uint8_t* data = in.Bytes(data_size, "data");

    const auto find = [&](const char* name) -> const Field* {
        for (const Field& f : fields) {
            if (f.name == name) {
                if (f.offset + core::ScalarSize(f.type) > point_step) {
                    in.Fail(std::string("field ") + name + " at offset " +
                            std::to_string(f.offset) + " does not fit in point_step " +
                            std::to_string(point_step));
                }
                return &f;
            }
        }
        return nullptr;
    };
    const Field* xyz[3] = {find("x"), find("y"), find("z")};
    for (int a = 0; a < 3; ++a) {
        const char* axis = a == 0 ? "x" : a == 1 ? "y" : "z";
        if (xyz[a] == nullptr) {
            std::string names;
            for (const Field& f : fields) names += (names.empty() ? "" : ", ") + f.name;
            in.Fail(std::string("the cloud has no field ") + axis +
                    " (its fields: " + (names.empty() ? "none" : names) + ")");
        }
        if (xyz[a]->type != core::ScalarType::kF32 && xyz[a]->type != core::ScalarType::kF64) {
            in.Fail(std::string("field ") + axis + " is not float32 or float64");
        }
    }
    const Field* intensity = find("intensity");
    const Field* time = nullptr;
    for (const auto& [name, kind] : {std::pair{"t", PointTimeField::kOusterT},
                                     std::pair{"time", PointTimeField::kVelodyneTime},
                                     std::pair{"timestamp", PointTimeField::kAbsoluteTimestamp},
                                     std::pair{"offset_time", PointTimeField::kOffsetTime}}) {
        if ((time = find(name)) != nullptr) {
            cloud.time_field = kind;
            break;
        }
    }
    const uint64_t points = static_cast<uint64_t>(height) * width;
    if (points > 0 && (point_step == 0 || row_step < static_cast<uint64_t>(width) * point_step ||
                       static_cast<uint64_t>(row_step) * (height - 1) +
                               static_cast<uint64_t>(width) * point_step >
                           data_size)) {
        in.Fail(std::to_string(height) + " x " + std::to_string(width) + " points of " +
                std::to_string(point_step) + " bytes (rows of " + std::to_string(row_step) +
                ") do not fit in " + std::to_string(data_size) + " bytes of data");
    }
    cloud.points.reserve(points);
    if (intensity != nullptr) cloud.intensity.reserve(points);
    if (time != nullptr) cloud.time_ns.reserve(points);
    for (uint32_t r = 0; r < height; ++r) {
        const uint8_t* row = data + static_cast<size_t>(r) * row_step;
        for (uint32_t c = 0; c < width; ++c) {
            const uint8_t* p = row + static_cast<size_t>(c) * point_step;
            const Eigen::Vector3d xyz_value(
                core::LoadAsDouble(p + xyz[0]->offset, xyz[0]->type, big_endian),
                core::LoadAsDouble(p + xyz[1]->offset, xyz[1]->type, big_endian),
                core::LoadAsDouble(p + xyz[2]->offset, xyz[2]->type, big_endian));
            if (!xyz_value.allFinite()) {
                ++cloud.dropped;
                continue;
            }
            cloud.points.push_back(xyz_value);
            if (intensity != nullptr) {
                cloud.intensity.push_back(static_cast<float>(
                    core::LoadAsDouble(p + intensity->offset, intensity->type, big_endian)));
            }
            if (time != nullptr) {
                const double v = core::LoadAsDouble(p + time->offset, time->type, big_endian);
                int64_t t = 0;
                if (cloud.time_field == PointTimeField::kAbsoluteTimestamp) {
                    const double ns = v > 1e12 ? v : v * 1e9;
                    if (!(ns >= 0.0 && ns < kMaxStampNs))
                        in.Fail("a point's timestamp is out of range");
                    t = std::llround(ns);
                } else {
                    const double ns =
                        cloud.time_field == PointTimeField::kVelodyneTime ? v * 1e9 : v;
                    if (!(std::abs(ns) <= kMaxPointOffsetNs)) {
                        in.Fail("a point's time is more than 1000 s from the cloud's stamp");
                    }
                    t = cloud.header.stamp_ns + std::llround(ns);
                }
                cloud.time_ns.push_back(t);
            }
        }
    }
    return cloud;
}

std::vector<StampedTransform> DecodeTfMessage(const Message& message, const std::string& file) {
    MessageReader in(message, file);
    const uint32_t n = in.Count("transforms", 56);  // at least the pose's seven doubles
    std::vector<StampedTransform> out(n);
    for (StampedTransform& t : out) {
        const Header h = in.ReadHeader();
        t.stamp_ns = h.stamp_ns;
        t.parent = h.frame_id;
        t.child = in.String("child_frame_id");
        t.T_parent_child = in.Pose("transform");
        if (t.parent.empty() || t.child.empty()) in.Fail("a transform without its frame names");
    }
    return out;
}

Odometry DecodeOdometry(const Message& message, const std::string& file) {
    MessageReader in(message, file);
    Odometry odometry;
    odometry.header = in.ReadHeader();
    odometry.child = in.String("child_frame_id");
    odometry.T_frame_child = in.Pose("pose.pose");
    in.SkipDoubles(36, "pose.covariance");
    in.SkipDoubles(6 + 36, "twist");
    return odometry;
}

Imu DecodeImu(const Message& message, const std::string& file) {
    MessageReader in(message, file);
    Imu imu;
    imu.header = in.ReadHeader();
    // An IMU without an orientation estimate sends zeros (and covariance[0] = -1): kept as the
    // identity.
    Eigen::Vector4d q;
    for (int i = 0; i < 4; ++i) q[i] = in.Read<double>("orientation");
    if (q.norm() > 0.5) imu.orientation = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized();
    in.SkipDoubles(9, "orientation_covariance");
    imu.angular_velocity = in.Vector("angular_velocity");
    in.SkipDoubles(9, "angular_velocity_covariance");
    imu.linear_acceleration = in.Vector("linear_acceleration");
    in.SkipDoubles(9, "linear_acceleration_covariance");
    if (!imu.angular_velocity.allFinite() || !imu.linear_acceleration.allFinite()) {
        in.Fail("angular velocity or acceleration is not finite");
    }
    return imu;
}

}  // namespace strata::recordings
