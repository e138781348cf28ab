#include "strata/recordings/RecordedScans.hpp"

#include <algorithm>
#include <cmath>

#include "strata/core/Error.hpp"
#include "strata/core/FrameRange.hpp"

namespace strata::recordings {
namespace {

constexpr const char* kTf = "/tf";
constexpr const char* kTfStatic = "/tf_static";
// Deskewing poses each point by interpolating between poses looked up at most this far apart
// within its sweep: the trajectory between two tf samples is itself linear, so at 1 ms the
// interpolation adds well under a millimetre at road speeds.
constexpr int64_t kDeskewKnotNs = 1000000;
// A deskewed sweep's rays start where the sensor was at their points' instants, to within this:
// the sweep is cut into runs of points over which the sensor moves at most twice as far, each
// with one ray origin in the middle (at 10 m/s about 10 runs to a 0.1 s sweep).
constexpr double kRayOriginToleranceM = 0.025;
// A sweep whose points' times span more than this is damaged (spinning LiDARs take 0.05-0.2 s).
constexpr int64_t kMaxSweepNs = 10LL * 1000000000LL;

std::string TopicList(const RecordingInfo& info, const std::string& type) {
    std::string names;
    for (const Topic& t : info.topics) {
        if (type.empty() || IsType(t, type)) names += (names.empty() ? "" : ", ") + t.name;
    }
    return names.empty() ? "none" : names;
}

std::string ChoosePointsTopic(const RecordingInfo& info, const std::string& wanted) {
    const std::string type = "sensor_msgs/PointCloud2";
    if (!wanted.empty()) {
        const Topic* t = info.Find(wanted);
        if (t == nullptr) {
            throw NotFoundError(info.path.string() + ": no topic " + wanted +
                                " (its PointCloud2 topics: " + TopicList(info, type) + ")");
        }
        if (!IsType(*t, type)) {
            throw InvalidArgumentError(info.path.string() + ": topic " + wanted + " holds " +
                                       t->type + ", not " + type);
        }
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

Eigen::Isometry3d Interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                              double alpha) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = (1.0 - alpha) * a.translation() + alpha * b.translation();
    T.linear() = Eigen::Quaterniond(a.rotation())
                     .slerp(alpha, Eigen::Quaterniond(b.rotation()))
                     .toRotationMatrix();
    return T;
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
    if (!options.odom_topic.empty()) {
        const Topic* odom = info.Find(options.odom_topic);
        if (odom == nullptr) {
            throw NotFoundError(file + ": no topic " + options.odom_topic +
                                " (its Odometry topics: " + TopicList(info, "nav_msgs/Odometry") +
                                ")");
        }
        if (!IsType(*odom, "nav_msgs/Odometry")) {
            throw InvalidArgumentError(file + ": topic " + options.odom_topic + " holds " +
                                       odom->type + ", not nav_msgs/Odometry");
        }
        topics.push_back(options.odom_topic);
    } else if (info.Find(kTf) != nullptr) {
        topics.emplace_back(kTf);
    }
    std::string odom_frame;
    s.recording_->Read(topics, [&](const Message& m) {
        const std::string& topic = m.topic->name;
        if (topic == s.points_topic_) {
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

    if (s.tree_.Frames().empty()) {
        throw NotFoundError(file + ": no poses: the recording has no /tf" +
                            std::string(options.odom_topic.empty() ? "" : " or odometry") +
                            " (give poses another way, or wait for strata's odometry)");
    }
    s.fixed_frame_ = !options.fixed_frame.empty() ? options.fixed_frame
                     : !odom_frame.empty()        ? odom_frame
                                                  : s.tree_.Root();
    // Every sweep posed at its stamp, checked now: a refusal comes before anything is written.
    for (size_t i = 0; i < s.sweeps_.size(); ++i) {
        const Sweep& w = s.sweeps_[i];
        if (w.frame.empty()) throw FormatError(file + ": " + s.Name(i) + " has no frame_id");
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
    size_t poses = SIZE_MAX;
    bool moving = false;
    for (const TransformTree::EdgeSummary& e :
         s.tree_.EdgesBetween(s.fixed_frame_, s.sweeps_.front().frame)) {
        if (e.is_static) continue;
        moving = true;
        poses = std::min(poses, e.samples);
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
    scan.T_world_sensor = tree_.Lookup(fixed_frame_, w.frame, w.stamp_ns);
    scan.time_s = static_cast<double>(w.stamp_ns) * 1e-9;
    scan.source = file + ": " + Name(i);
    if (!deskew_ || cloud.time_ns.empty()) {
        scan.intensity = std::move(cloud.intensity);
        scan.points = std::move(cloud.points);
        return scan;
    }
    // Poses of the sensor relative to its pose at the stamp, at knots across the sweep.
    const auto [lo, hi] = std::minmax_element(cloud.time_ns.begin(), cloud.time_ns.end());
    const int64_t t0 = *lo, span = *hi - *lo;
    if (span < 0 || span > kMaxSweepNs) {
        throw FormatError(file + ": " + Name(i) + ": its points' times span " + FormatStamp(span) +
                          " s; a sweep takes a fraction of a second");
    }
    const size_t knots = static_cast<size_t>(span / kDeskewKnotNs) + 2;
    const Eigen::Isometry3d T_stamp_world = scan.T_world_sensor.inverse();
    std::vector<Eigen::Isometry3d> relative(knots);
    for (size_t k = 0; k < knots; ++k) {
        const int64_t t = t0 + static_cast<int64_t>(
                                   std::llround(static_cast<double>(span) * static_cast<double>(k) /
                                                static_cast<double>(knots - 1)));
        try {
            relative[k] = T_stamp_world * tree_.Lookup(fixed_frame_, w.frame, t);
        } catch (const RefusedError& e) {
            throw RefusedError(file + ": " + Name(i) + ": its points' times reach " +
                               FormatStamp(t) + ": " + e.what());
        }
    }
    // Runs of knot intervals over which the sensor moves at most twice the tolerance.
    std::vector<size_t> run_of(knots - 1);
    for (size_t a = 0; a + 1 < knots;) {
        size_t b = a + 1;
        while (b + 1 < knots &&
               (relative[b + 1].translation() - relative[a].translation()).norm() <=
                   2.0 * kRayOriginToleranceM) {
            ++b;
        }
        std::fill(run_of.begin() + static_cast<ptrdiff_t>(a),
                  run_of.begin() + static_cast<ptrdiff_t>(b), scan.ray_origins.size());
        scan.ray_origins.push_back(
            {0, 0.5 * (relative[a].translation() + relative[b].translation())});
        a = b;
    }
    // The points deskewed, then stably ordered by run (a counting sort).
    const size_t n = cloud.points.size();
    std::vector<size_t> run(n);
    std::vector<size_t> count(scan.ray_origins.size() + 1, 0);
    std::vector<Eigen::Vector3d> points(n);
    const double scale =
        span > 0 ? static_cast<double>(knots - 1) / static_cast<double>(span) : 0.0;
    for (size_t j = 0; j < n; ++j) {
        const double u = static_cast<double>(cloud.time_ns[j] - t0) * scale;
        const size_t k = std::min(static_cast<size_t>(u), knots - 2);
        points[j] =
            Interpolate(relative[k], relative[k + 1], u - static_cast<double>(k)) * cloud.points[j];
        run[j] = run_of[k];
        ++count[run[j] + 1];
    }
    std::vector<core::RayOrigin> origins;
    for (size_t r = 0; r < scan.ray_origins.size(); ++r) {
        // Runs no point fell into (a gap in the sweep's times) are left out.
        if (count[r + 1] > 0) origins.push_back({count[r], scan.ray_origins[r].origin});
        count[r + 1] += count[r];
    }
    scan.ray_origins = std::move(origins);
    scan.points.resize(n);
    scan.intensity.resize(cloud.intensity.size());
    for (size_t j = 0; j < n; ++j) {
        const size_t to = count[run[j]]++;
        scan.points[to] = points[j];
        if (!cloud.intensity.empty()) scan.intensity[to] = cloud.intensity[j];
    }
    return scan;
}

}  // namespace strata::recordings
