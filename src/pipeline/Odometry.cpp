#include "strata/pipeline/Odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <utility>

#include "strata/core/Error.hpp"
#include "strata/io/PoseFiles.hpp"
#include "strata/registration/Surface.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::pipeline {

namespace detail {

// The stored map's occupied points (its voxels' point means) for a session's odometry, in square
// blocks of kBlockM by kBlockM (x, y). A block joins the odometry's local map once the whole of
// it lies within reach of the sensor, and again after the drive has been so far from it that the
// local map forgot all of it (registration::OdometryConfig::max_range_m). A tile is read once,
// when the first block that reaches into it is wanted; its points are kept by block.
class StoredMapFeed {
public:
    StoredMapFeed(const store::MapStore& map, const store::Snapshot& snapshot, double reach_m,
                  double cell_m)
        : reader_(map, snapshot, 0), reach_m_(reach_m), cell_m_(cell_m) {}

    // Adds the blocks that came within reach of `sensor` (map frame) to the local map, and
    // forgets those the local map has dropped since they joined it.
    void Around(const Eigen::Vector3d& sensor, registration::Odometry& odometry) {
        const Eigen::Vector2d at = sensor.head<2>();
        for (auto it = in_local_map_.begin(); it != in_local_map_.end();) {
            const bool dropped = Distance(*it, at) - kHalfDiagonalM - cell_m_ > reach_m_;
            it = dropped ? in_local_map_.erase(it) : std::next(it);
        }
        const Block lo = BlockOf(at - Eigen::Vector2d::Constant(reach_m_));
        const Block hi = BlockOf(at + Eigen::Vector2d::Constant(reach_m_));
        std::vector<Eigen::Vector3d> points;
        for (int64_t bx = lo.first; bx <= hi.first; ++bx) {
            for (int64_t by = lo.second; by <= hi.second; ++by) {
                const Block b{bx, by};
                if (Distance(b, at) + kHalfDiagonalM > reach_m_ || in_local_map_.count(b)) continue;
                ReadTilesUnder(b);
                in_local_map_.insert(b);
                const auto found = blocks_.find(b);
                if (found == blocks_.end()) continue;
                points.insert(points.end(), found->second.begin(), found->second.end());
            }
        }
        if (points.empty()) return;
        odometry.AddToMap(points);
        used_ += points.size();
    }

    [[nodiscard]] size_t used() const { return used_; }

private:
    static constexpr double kBlockM = 10.0;
    static constexpr double kHalfDiagonalM = kBlockM * 0.70710678118654752;
    using Block = std::pair<int64_t, int64_t>;

    static Block BlockOf(const Eigen::Vector2d& p) {
        return {static_cast<int64_t>(std::floor(p.x() / kBlockM)),
                static_cast<int64_t>(std::floor(p.y() / kBlockM))};
    }
    static double Distance(const Block& b, const Eigen::Vector2d& p) {
        const Eigen::Vector2d centre((static_cast<double>(b.first) + 0.5) * kBlockM,
                                     (static_cast<double>(b.second) + 0.5) * kBlockM);
        return (centre - p).norm();
    }
    // The points of every tile the block reaches into, sorted into blocks, each tile once.
    void ReadTilesUnder(const Block& b) {
        const Eigen::Vector2d lo(static_cast<double>(b.first) * kBlockM,
                                 static_cast<double>(b.second) * kBlockM);
        for (const store::TileKey& key :
             reader_.Tiles(lo, lo + Eigen::Vector2d::Constant(kBlockM), 0)) {
            if (!read_.insert(key).second) continue;
            const auto fused = reader_.Fused(key);
            if (!fused) continue;
            for (const Eigen::Vector3d& p : registration::OccupiedPoints(*fused)) {
                blocks_[BlockOf(p.head<2>())].push_back(p);
            }
        }
    }

    store::TileReader reader_;
    double reach_m_;
    double cell_m_;
    std::set<store::TileKey> read_;
    std::map<Block, std::vector<Eigen::Vector3d>> blocks_;
    std::set<Block> in_local_map_;
    size_t used_ = 0;
};

}  // namespace detail

struct SessionOdometry::State {
    registration::OdometryConfig config;
    std::optional<OdometryStart> start;
    std::optional<registration::Gyro> gyro;
    // Made at the first scan: started in a map, its world is where that scan's alignment puts it.
    std::optional<registration::Odometry> odometry;
    Eigen::Isometry3d T_world_first = Eigen::Isometry3d::Identity();
    std::optional<MapAlignment> alignment;
    std::optional<detail::StoredMapFeed> feed;

    // The odometry for the first scan, `scan`: in a world of its own, or where the scan's
    // alignment to the stored map puts it, with the map's points to come.
    void Begin(const core::Scan& scan) {
        std::optional<Eigen::Isometry3d> first;
        if (start) {
            if (start->map == nullptr) throw InvalidArgumentError("OdometryStart: no map");
            const MapAlignment a = AlignToMap(*start->map, start->snapshot, {scan.points, 1, true},
                                              start->align.guess, start->align.options);
            if (start->on_aligned) start->on_aligned(a);
            RequireAccepted(a,
                            "the first scan's alignment to the map" +
                                (scan.source.empty() ? std::string() : " (" + scan.source + ")"));
            alignment = a;
            T_world_first = a.result.T_map_source;
            first = T_world_first;
            feed.emplace(*start->map, start->snapshot, config.max_range_m, config.voxel_m);
        }
        odometry.emplace(config, first);
        if (gyro) odometry->PredictRotationBy(*gyro);
    }
};

SessionOdometry::SessionOdometry(const registration::OdometryConfig& config,
                                 std::optional<OdometryStart> start)
    : state_(std::make_unique<State>()) {
    config.Validate();
    state_->config = config;
    state_->start = std::move(start);
}
SessionOdometry::~SessionOdometry() = default;
SessionOdometry::SessionOdometry(SessionOdometry&&) noexcept = default;
SessionOdometry& SessionOdometry::operator=(SessionOdometry&&) noexcept = default;

registration::OdometryStep SessionOdometry::Register(const core::Scan& scan) {
    State& s = *state_;
    if (!s.odometry) s.Begin(scan);
    if (s.feed) {
        const std::vector<Eigen::Isometry3d>& poses = s.odometry->poses();
        const Eigen::Isometry3d& last = poses.empty() ? s.T_world_first : poses.back();
        s.feed->Around(last.translation(), *s.odometry);
    }
    return s.odometry->Register(scan);
}

void SessionOdometry::PredictRotationBy(registration::Gyro gyro) {
    state_->gyro = std::move(gyro);
    if (state_->odometry) state_->odometry->PredictRotationBy(*state_->gyro);
}

const std::vector<Eigen::Isometry3d>& SessionOdometry::poses() const {
    static const std::vector<Eigen::Isometry3d> kNone;
    return state_->odometry ? state_->odometry->poses() : kNone;
}

const std::optional<MapAlignment>& SessionOdometry::alignment() const { return state_->alignment; }

std::optional<size_t> SessionOdometry::map_points_used() const {
    if (!state_->start) return std::nullopt;
    return state_->feed ? state_->feed->used() : 0;
}

EstimatedTrajectory EstimateTrajectory(const ScanSource& source, const OdometryOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    SessionOdometry odometry(options.config, options.start);
    EstimatedTrajectory out;
    const recordings::RecordedScans* recording = source.recording();
    if (recording != nullptr && !recording->imu().angular_velocity.empty()) {
        const recordings::ImuReadings& imu = recording->imu();
        try {
            odometry.PredictRotationBy(registration::Gyro(imu.times_s, imu.angular_velocity));
        } catch (const InvalidArgumentError& e) {  // readings out of order: a broken recording
            out.gyro_failure = e.what();
        }
    }
    ReportProgress(options.progress, "odometry", 0, source.size());
    for (size_t i = 0; i < source.size(); ++i) {
        const core::Scan scan = source.Read(i);
        const registration::OdometryStep step = odometry.Register(scan);
        if (!step.registered) {
            const std::string why =
                "scan " + std::to_string(i) + " (" + scan.source + "): " + step.failure;
            if (!options.skip_failures) {
                throw RefusedError(why +
                                   "; nothing written (--odometry-on-failure skip leaves "
                                   "such scans out)");
            }
            out.skipped.push_back(why);
        } else {
            if (!out.poses.empty()) {
                out.length_m +=
                    (step.T_world_sensor.translation() - out.poses.back().translation()).norm();
            }
            if (out.poses.empty()) out.ground = step.ground;
            if (!step.degenerate.empty()) {
                out.degenerate.push_back("scan " + std::to_string(i) + " (" + scan.source +
                                         "): " + step.degenerate);
            }
            if (step.gyro) ++out.gyro_predicted;
            out.poses.push_back(step.T_world_sensor);
            out.times_s.push_back(scan.time_s);
            out.scans.push_back(i);
        }
        ReportProgress(options.progress, "odometry", i + 1, source.size());
    }
    if (out.poses.empty()) throw RefusedError("the odometry registered none of the scans");
    out.alignment = odometry.alignment();
    out.map_points_used = odometry.map_points_used();
    if (recording != nullptr) {
        const recordings::ImuReadings& imu = recording->imu();
        out.imu_note = imu.note;
        // In a stored map the map's up holds; else the IMU's gravity turns the poses level.
        if (!options.start && !imu.topic.empty()) {
            out.imu = registration::LevelFromAccelerometer({imu.times_s, imu.specific_force},
                                                           out.times_s, out.poses);
            if (out.imu->found) {
                for (Eigen::Isometry3d& T : out.poses) T = out.imu->R_level * T;
            }
        }
    }
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
}

std::vector<std::string> OdometryWarnings(const EstimatedTrajectory& t) {
    constexpr size_t kNamed = 3;  // degenerate scans come in runs: the first few say where
    std::vector<std::string> lines;
    for (const std::string& skipped : t.skipped) lines.push_back("left out " + skipped);
    if (!t.degenerate.empty()) {
        lines.push_back(std::to_string(t.degenerate.size()) + " of " +
                        std::to_string(t.poses.size()) +
                        " scans were degenerate (a motion the matches did not fix kept the "
                        "prediction); the first:");
        for (size_t k = 0; k < std::min(kNamed, t.degenerate.size()); ++k) {
            lines.push_back("  " + t.degenerate[k]);
        }
    }
    return lines;
}

std::string DescribePrediction(const EstimatedTrajectory& t) {
    if (t.gyro_predicted == 0) {
        return "prediction: constant velocity" +
               (t.gyro_failure.empty() ? std::string()
                                       : " (the IMU's gyro was not used: " + t.gyro_failure + ")");
    }
    // The first scan has no prediction; a scan whose span the readings miss keeps the model's.
    return "prediction: rotation from the IMU's gyro (" + std::to_string(t.gyro_predicted) +
           " of " + std::to_string(t.poses.size()) + " scans), translation at constant velocity";
}

std::string DescribeGravity(const EstimatedTrajectory& t) {
    char text[400];
    if (t.map_points_used) {
        std::snprintf(text, sizeof(text),
                      "gravity: the map's z (the session started in the map; the odometry took "
                      "in %zu of its points along the drive)",
                      *t.map_points_used);
        return text;
    }
    if (t.imu && t.imu->found) {
        const registration::ImuLevel& i = *t.imu;
        std::snprintf(text, sizeof(text),
                      "gravity: the IMU's accelerometer (%s; %zu readings over %.1f s against "
                      "the poses, RMS %.3f m; g %.3f m/s^2): the first scan was tilted %.2f "
                      "deg%s",
                      t.imu_note.c_str(), i.readings, i.span_s, i.residual_m, i.g, i.first_tilt_deg,
                      t.ground && t.ground->found ? "" : " (no ground plane in the first scan)");
        return text;
    }
    const std::string imu = t.imu ? "the IMU's readings were not used (" + t.imu->failure + "); "
                            : !t.imu_note.empty() ? "no IMU (" + t.imu_note + "); "
                                                  : "";
    if (!t.ground) return "gravity: " + imu + "the first scan's z (levelling was off)";
    const registration::GroundLevel& g = *t.ground;
    if (!g.found) {
        std::snprintf(text, sizeof(text),
                      "no ground plane in the first scan (%s): the map's z is the first scan's",
                      g.failure.c_str());
    } else {
        std::snprintf(text, sizeof(text),
                      "the first scan's ground plane%s: the scan was tilted %.2f deg, %zu returns "
                      "on the plane, RMS %.3f m, sensor %.2f m above it",
                      imu.empty() ? " (no IMU read)" : "", g.tilt_deg, g.points, g.rms_m,
                      g.height_m);
    }
    return "gravity: " + imu + text;
}

void RequireTrajectoryFile(const std::filesystem::path& out) {
    const std::string extension = out.extension().string();
    if (extension != ".txt" && extension != ".tum") {
        throw InvalidArgumentError(out.string() +
                                   ": a trajectory file ends in .txt (KITTI) or .tum (TUM)");
    }
}

void WriteTrajectory(const std::filesystem::path& out, const EstimatedTrajectory& trajectory) {
    RequireTrajectoryFile(out);
    if (out.extension() == ".txt") {
        io::WriteKittiPoses(out, trajectory.poses);
        return;
    }
    std::vector<io::StampedPose> stamped;
    for (size_t k = 0; k < trajectory.poses.size(); ++k) {
        stamped.push_back({trajectory.times_s[k], trajectory.poses[k]});
    }
    io::WriteTumPoses(out, stamped);
}

}  // namespace strata::pipeline
