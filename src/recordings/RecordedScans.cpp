#include "strata/recordings/RecordedScans.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "strata/core/Error.hpp"
#include "strata/core/FrameRange.hpp"
#include "strata/recordings/Deskew.hpp"

namespace strata::recordings {
namespace {

constexpr const char* kTf = "/tf";
constexpr const char* kTfStatic = "/tf_static";
std::string TopicList(const RecordingInfo& info, const std::string& type) {
    std::string names;
    for (const Topic& t : info.topics) {
        if (type.empty() || IsType(t, type)) names += (names.empty() ? "" : ", ") + t.name;
    }
    return names.empty() ? "none" : names;
}

// The named topic, which must exist and hold `type` ("sensor_msgs/Imu").
void RequireTopic(const RecordingInfo& info, const std::string& name, const std::string& type) {
    const Topic* t = info.Find(name);
    if (t == nullptr) {
        throw NotFoundError(info.path.string() + ": no topic " + name + " (its " +
                            type.substr(type.find('/') + 1) + " topics: " + TopicList(info, type) +
                            ")");
    }
    if (!IsType(*t, type)) {
        throw InvalidArgumentError(info.path.string() + ": topic " + name + " holds " + t->type +
                                   ", not " + type);
    }
}

std::string ChoosePointsTopic(const RecordingInfo& info, const std::string& wanted) {
    const std::string type = "sensor_msgs/PointCloud2";
    if (!wanted.empty()) {
        RequireTopic(info, wanted, type);
        return wanted;
    }
    std::vector<std::string> clouds;
    for (const Topic& t : info.topics) {
        if (IsType(t, type)) clouds.push_back(t.name);
    }
    if (clouds.empty()) {
        throw NotFoundError(info.path.string() + ": no " + type +
                            " topic (its topics: " + TopicList(info, "") + ")");
    }
    if (clouds.size() > 1) {
        throw InvalidArgumentError(info.path.string() + ": " + std::to_string(clouds.size()) +
                                   " PointCloud2 topics (" + TopicList(info, type) +
                                   "): choose one with --points-topic");
    }
    return clouds.front();
}

// The IMU topic whose readings go to the odometry: the one named, else the recording's one Imu
// topic; empty (and `note` says why) when there is none to read.
std::string ChooseImuTopic(const RecordingInfo& info, const RecordedScanOptions& options,
                           std::string* note) {
    const std::string type = "sensor_msgs/Imu";
    if (!options.imu_topic.empty()) {
        RequireTopic(info, options.imu_topic, type);
        return options.imu_topic;
    }
    if (!options.imu) {
        *note = "not read (--no-imu)";
        return "";
    }
    std::vector<std::string> imus;
    for (const Topic& t : info.topics) {
        if (IsType(t, type)) imus.push_back(t.name);
    }
    if (imus.size() == 1) return imus.front();
    *note = imus.empty() ? "the recording has no sensor_msgs/Imu topic"
                         : std::to_string(imus.size()) + " Imu topics (" + TopicList(info, type) +
                               "): choose one with --imu-topic";
    return "";
}

}  // namespace

RecordedScans RecordedScans::Open(const std::filesystem::path& path,
                                  const RecordedScanOptions& options) {
    RecordedScans s;
    s.recording_ = Recording::Open(path);
    const RecordingInfo& info = s.recording_->info();
    const std::string file = path.string();
    s.points_topic_ = ChoosePointsTopic(info, options.points_topic);

    std::vector<std::string> topics{s.points_topic_};
    if (info.Find(kTfStatic) != nullptr) topics.emplace_back(kTfStatic);
    s.posed_ = options.posed;  // else only the sweeps (and /tf_static, the sensor's mounting)
    if (s.posed_ && !options.odom_topic.empty()) {
        RequireTopic(info, options.odom_topic, "nav_msgs/Odometry");
        topics.push_back(options.odom_topic);
    } else if (s.posed_ && info.Find(kTf) != nullptr) {
        topics.emplace_back(kTf);
    }
    std::string imu_topic;
    if (!s.posed_) {
        imu_topic = ChooseImuTopic(info, options, &s.imu_.note);
        if (!imu_topic.empty()) topics.push_back(imu_topic);
    }
    std::vector<Imu> imu;
    std::string odom_frame;
    s.recording_->Read(topics, [&](const Message& m) {
        const std::string& topic = m.topic->name;
        if (topic == imu_topic) {
            imu.push_back(DecodeImu(m, file));
        } else if (topic == s.points_topic_) {
            Header h = DecodeHeader(m, file);
            s.sweeps_.push_back({h.stamp_ns, std::move(h.frame_id), m.location});
        } else if (topic == kTf || topic == kTfStatic) {
            for (const StampedTransform& t : DecodeTfMessage(m, file)) {
                s.tree_.Add(t, topic == kTfStatic);
            }
        } else {
            const Odometry o = DecodeOdometry(m, file);
            s.tree_.Add({o.header.stamp_ns, o.header.frame_id, o.child, o.T_frame_child}, false);
            odom_frame = o.header.frame_id;
        }
    });
    if (s.sweeps_.empty())
        throw NotFoundError(file + ": topic " + s.points_topic_ + " holds no message");
    std::stable_sort(s.sweeps_.begin(), s.sweeps_.end(),
                     [](const Sweep& a, const Sweep& b) { return a.stamp_ns < b.stamp_ns; });
    const auto [begin, end] = core::ParseFrameRange(options.frames, s.sweeps_.size());
    s.first_ = begin;
    s.sweeps_ = std::vector<Sweep>(s.sweeps_.begin() + static_cast<std::ptrdiff_t>(begin),
                                   s.sweeps_.begin() + static_cast<std::ptrdiff_t>(end));

    for (size_t i = 0; i < s.sweeps_.size(); ++i) {
        if (s.sweeps_[i].frame.empty()) {
            throw FormatError(file + ": " + s.Name(i) + " has no frame_id");
        }
    }
    if (!s.posed_) {
        // One sensor's sweeps, each in its frame at its stamp: what an odometry chains.
        s.fixed_frame_ = s.sweeps_.front().frame;
        for (size_t i = 0; i < s.sweeps_.size(); ++i) {
            if (s.sweeps_[i].frame != s.fixed_frame_) {
                throw InvalidArgumentError(file + ": " + s.Name(i) + " is in frame " +
                                           s.sweeps_[i].frame + ", the first in " + s.fixed_frame_ +
                                           ": one sensor's sweeps are needed");
            }
        }
        s.ReadImu(imu_topic, imu);
        s.times_ = options.deskew;
        s.deskew_note_ = options.deskew
                             ? "not posed by the recording: the odometry deskews the sweeps that "
                               "carry their points' times"
                             : "not posed by the recording, not deskewed (--no-deskew)";
        return s;
    }
    if (s.tree_.Frames().empty()) {
        throw NotFoundError(file + ": no poses: the recording has no /tf" +
                            std::string(options.odom_topic.empty() ? "" : " or odometry") +
                            " (give poses another way, or estimate them: --odometry)");
    }
    s.fixed_frame_ = !options.fixed_frame.empty() ? options.fixed_frame
                     : !odom_frame.empty()        ? odom_frame
                                                  : s.tree_.Root();
    // A tree of mountings alone poses every sweep at one place: a sensor that stood still, or
    // (far more often) a recording whose trajectory was never recorded.
    size_t poses = SIZE_MAX;
    bool moving = false;
    for (const TransformTree::EdgeSummary& e :
         s.tree_.EdgesBetween(s.fixed_frame_, s.sweeps_.front().frame)) {
        if (e.is_static) continue;
        moving = true;
        poses = std::min(poses, e.samples);
    }
    if (!moving && s.sweeps_.size() > 1) {
        throw NotFoundError(file +
                            ": no trajectory: the tf tree holds only fixed transforms from " +
                            s.fixed_frame_ + " to " + s.sweeps_.front().frame +
                            " (/tf_static), so every sweep would lie at one pose (estimate the "
                            "poses: --odometry)");
    }
    // Every sweep posed at its stamp, checked now: a refusal comes before anything is written.
    for (size_t i = 0; i < s.sweeps_.size(); ++i) {
        const Sweep& w = s.sweeps_[i];
        const auto span = s.tree_.Span(s.fixed_frame_, w.frame);
        if (span && (w.stamp_ns < span->first || w.stamp_ns > span->second)) {
            throw RefusedError(file + ": " + s.Name(i) + " lies outside the trajectory from " +
                               s.fixed_frame_ + " to " + w.frame + ", known from " +
                               FormatStamp(span->first) + " to " + FormatStamp(span->second) +
                               " (choose the sweeps inside it with --frames)");
        }
    }

    // Deskew when asked, when the clouds carry per-point times and when the sensor moves in
    // the fixed frame with poses denser than the sweeps.
    if (!options.deskew) {
        s.deskew_note_ = "not deskewed (--no-deskew)";
        return s;
    }
    PointTimeField field = PointTimeField::kNone;
    s.recording_->ReadMessage(s.sweeps_.front().location, [&](const Message& m) {
        field = DecodePointCloud2(m, file).time_field;
    });
    if (field == PointTimeField::kNone) {
        s.deskew_note_ =
            "not deskewed: the clouds have no per-point time field (t, time, timestamp or "
            "offset_time)";
        return s;
    }
    if (!moving) {
        s.deskew_note_ = "not deskewed: the sensor does not move in " + s.fixed_frame_;
        return s;
    }
    if (poses <= s.sweeps_.size()) {
        s.deskew_note_ = "not deskewed: " + std::to_string(poses) + " poses are no denser than " +
                         std::to_string(s.sweeps_.size()) + " sweeps";
        return s;
    }
    static const char* const kFieldNames[] = {"", "t", "time", "timestamp", "offset_time"};
    s.deskew_ = true;
    s.deskew_note_ = std::string("deskewed by the per-point field '") +
                     kFieldNames[static_cast<int>(field)] + "' (" + std::to_string(poses) +
                     " poses for " + std::to_string(s.sweeps_.size()) + " sweeps)";
    return s;
}

void RecordedScans::ReadImu(const std::string& topic, const std::vector<Imu>& readings) {
    if (topic.empty()) return;
    if (readings.empty()) {
        imu_.note = topic + " holds no message";
        return;
    }
    // The IMU's mounting on the sensor: the same frame, or fixed transforms between them.
    const std::string& frame = readings.front().header.frame_id;
    Eigen::Matrix3d R_sensor_imu = Eigen::Matrix3d::Identity();
    if (frame != fixed_frame_) {
        try {
            R_sensor_imu =
                tree_.Lookup(fixed_frame_, frame, readings.front().header.stamp_ns).linear();
        } catch (const Error& e) {
            imu_.note = topic + " is in frame " + frame +
                        ", which /tf_static does not connect to " + fixed_frame_ + " (" + e.what() +
                        "): not used";
            return;
        }
    }
    imu_.topic = topic;
    for (const Imu& r : readings) {
        imu_.times_s.push_back(static_cast<double>(r.header.stamp_ns) * 1e-9);
        imu_.specific_force.push_back(R_sensor_imu * r.linear_acceleration);
        imu_.angular_velocity.push_back(R_sensor_imu * r.angular_velocity);
    }
    const double span = imu_.times_s.back() - imu_.times_s.front();
    char text[160];
    std::snprintf(text, sizeof(text), ": %zu readings at %.0f Hz in frame ", readings.size(),
                  span > 0.0 ? static_cast<double>(readings.size() - 1) / span : 0.0);
    imu_.note = topic + text + frame;
}

std::string RecordedScans::Name(size_t i) const {
    return "sweep " + std::to_string(first_ + i) + " of " + points_topic_ + " (stamp " +
           FormatStamp(sweeps_[i].stamp_ns) + ")";
}

core::Scan RecordedScans::Read(size_t i) const {
    const Sweep& w = sweeps_.at(i);
    const std::string file = info().path.string();
    PointCloud cloud;
    recording_->ReadMessage(w.location,
                            [&](const Message& m) { cloud = DecodePointCloud2(m, file); });
    core::Scan scan;
    if (posed_) scan.T_world_sensor = tree_.Lookup(fixed_frame_, w.frame, w.stamp_ns);
    scan.time_s = static_cast<double>(w.stamp_ns) * 1e-9;
    scan.source = file + ": " + Name(i);
    scan.intensity = std::move(cloud.intensity);
    scan.points = std::move(cloud.points);
    if (!deskew_ && !times_) return scan;
    scan.times_s.reserve(cloud.time_ns.size());
    for (const int64_t t : cloud.time_ns) {
        scan.times_s.push_back(static_cast<float>(static_cast<double>(t - w.stamp_ns) * 1e-9));
    }
    if (!deskew_) {
        RequireSweepTimes(scan);
        return scan;
    }
    const Eigen::Isometry3d T_stamp_world = scan.T_world_sensor.inverse();
    Deskew(scan, [&](double tau) {
        const int64_t t = w.stamp_ns + std::llround(tau * 1e9);
        try {
            return Eigen::Isometry3d(T_stamp_world * tree_.Lookup(fixed_frame_, w.frame, t));
        } catch (const RefusedError& e) {
            throw RefusedError(file + ": " + Name(i) + ": its points' times reach " +
                               FormatStamp(t) + ": " + e.what());
        }
    });
    return scan;
}

}  // namespace strata::recordings
