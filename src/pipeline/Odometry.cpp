#include "strata/pipeline/Odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "strata/core/Error.hpp"
#include "strata/io/PoseFiles.hpp"

namespace strata::pipeline {

EstimatedTrajectory EstimateTrajectory(const ScanSource& source, const OdometryOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    registration::Odometry odometry(options.config);
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
    if (recording != nullptr) {
        const recordings::ImuReadings& imu = recording->imu();
        out.imu_note = imu.note;
        if (!imu.topic.empty()) {
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
