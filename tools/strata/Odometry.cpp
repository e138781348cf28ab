// strata odometry: poses for scans that came without them, written as a trajectory file
// (docs/odometry.md).
#include "strata/pipeline/Odometry.hpp"

#include <tbb/global_control.h>

#include <iostream>
#include <memory>

#include "Commands.hpp"
#include "Progress.hpp"
#include "ScanOptions.hpp"
#include "strata/core/Error.hpp"

namespace strata::tools {

namespace {

struct OdometryArgs {
    pipeline::ScanSpec scans;
    std::string poses_out;
    std::string on_failure = "stop";
    int threads = 0;
};

void Run(OdometryArgs args) {
    std::unique_ptr<tbb::global_control> limit;
    if (args.threads > 0) {
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      args.threads);
    }
    args.scans.require_poses = false;  // the odometry estimates them
    pipeline::OdometryOptions options;
    options.skip_failures = args.on_failure == "skip";
    options.progress = ProgressBars();
    pipeline::RequireTrajectoryFile(args.poses_out);  // before any scan is read
    const pipeline::ScanSource source =
        pipeline::ScanSource::Open(args.scans, Eigen::Vector3d::Zero());
    if (const recordings::RecordedScans* r = source.recording()) {
        std::cerr << "strata odometry: sweeps of " << r->points_topic() << " in "
                  << r->fixed_frame() << ", " << r->deskew_note() << "\n";
    }
    const pipeline::EstimatedTrajectory t = pipeline::EstimateTrajectory(source, options);
    for (const std::string& line : pipeline::OdometryWarnings(t)) {
        std::cerr << "strata odometry: " << line << "\n";
    }
    pipeline::WriteTrajectory(args.poses_out, t);
    std::cout << "odometry: " << t.poses.size() << " of " << source.size() << " scans from "
              << source.Describe() << ", " << t.length_m << " m in " << t.seconds << " s ("
              << 1e3 * t.seconds / static_cast<double>(source.size()) << " ms a scan); poses in "
              << args.poses_out << "\n"
              << pipeline::DescribePrediction(t) << "\n"
              << pipeline::DescribeGravity(t) << "\n";
}

}  // namespace

void RegisterOdometry(CLI::App& app) {
    auto args = std::make_shared<OdometryArgs>();
    CLI::App* cmd = app.add_subcommand(
        "odometry", "Estimate the poses of scans that have none (LiDAR odometry), no map written");
    cmd->footer(
        "Examples:\n"
        "  strata odometry --kitti drive/ --poses-out drive_poses.txt\n"
        "  strata odometry --scans scans/*.pcd --poses-out poses.tum --odometry-on-failure skip\n"
        "  strata odometry --bag drive.bag --points-topic /points_raw --poses-out poses.tum\n"
        "The first scan, turned level, defines the frame; .txt is written as KITTI 3x4 rows (the\n"
        "sensor in that frame), .tum as TUM. A recording's /tf is not read; its sweeps with\n"
        "per-point times are deskewed by the estimated motion (--no-deskew: not). A scan that "
        "cannot be registered stops the run and nothing is\n"
        "written, unless --odometry-on-failure skip (docs/odometry.md).");
    cmd->add_option("--kitti", args->scans.kitti,
                    "KITTI-layout sequence folder (poses.txt not needed, ignored when present)");
    AddRecordingOptions(*cmd, args->scans);
    cmd->add_option("--scans", args->scans.files,
                    "PCD, PLY, LAS, .bin or text files (.bz2 allowed), in driving order");
    AddBinFieldsOption(*cmd, args->scans.bin_fields);
    cmd->add_option("--frames", args->scans.frames,
                    "Frame range A:B of the sequence, or of the recording's sweeps (half-open)");
    cmd->add_option("--poses-out", args->poses_out, "Trajectory file: .txt (KITTI) or .tum (TUM)")
        ->required();
    cmd->add_option("--odometry-on-failure", args->on_failure,
                    "stop (nothing written) or skip (leave the scan out) when a scan cannot be "
                    "registered")
        ->check(CLI::IsMember({"stop", "skip"}))
        ->capture_default_str();
    cmd->add_option("--threads", args->threads, "Worker threads (0 = all cores)")
        ->capture_default_str();
    cmd->callback([args] { Run(*args); });
}

}  // namespace strata::tools
