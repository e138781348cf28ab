#include "RealPairs.hpp"

#include "strata/integration/Integrator.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PoseFiles.hpp"
#include "strata/registration/MapRegion.hpp"

namespace strata::registration::test {

namespace {

std::vector<Eigen::Isometry3d> SensorPoses(const std::filesystem::path& file,
                                           const Eigen::Isometry3d& Tr, size_t count) {
    std::vector<Eigen::Isometry3d> out;
    for (const Eigen::Isometry3d& P : io::ReadKittiPoses(file)) {
        if (out.size() == count) break;
        out.push_back(Tr.inverse() * P * Tr);
    }
    return out;
}

}  // namespace

Eigen::Isometry3d Off(const Eigen::Isometry3d& T) {
    const double d = 0.5 / std::sqrt(2.0);
    return PoseFromXyzYaw(d, -d, 0.0, 3.0) * T;
}

core::VoxelMap MapOf(const std::vector<std::vector<Eigen::Vector3d>>& scans,
                     const std::vector<Eigen::Isometry3d>& T_map_scan, double voxel_m) {
    core::VoxelMap map = core::VoxelMap::Create(voxel_m);
    integration::Integrator integrator(map, {});
    for (size_t i = 0; i < scans.size(); ++i) {
        core::Scan scan;
        scan.points = scans[i];
        scan.T_world_sensor = T_map_scan[i];
        integrator.Integrate(scan);
    }
    return map;
}

RegistrationResult RegisterScan(const core::VoxelMap& map, const std::vector<Eigen::Vector3d>& scan,
                                const Eigen::Isometry3d& guess) {
    RegistrationConfig config;
    config.min_source_range_m = kScanMinRangeM;
    config.max_source_range_m = kScanMaxRangeM;
    const Surface surface = Surface::FromPoints(
        OccupiedPoints(map, BoundsOf(scan, guess, kMapMarginM)), config.surface);
    return RegisterPoints(surface, scan, guess, config);
}

Kitti00 LoadKitti00(const std::filesystem::path& dir) {
    const io::KittiSequence seq = io::OpenKittiSequence(dir);
    const Eigen::Isometry3d Tr = io::ReadKittiCalibTr(dir / "calib.txt");
    Kitti00 k;
    for (size_t i = 0; i < 6; ++i) {
        k.scans.push_back(io::ReadKittiScan(seq, i).points);
        k.ground_truth.push_back(seq.T_world_sensor[i]);
    }
    k.orbslam2 = SensorPoses(dir / "poses_orbslam2.txt", Tr, 6);
    k.sptam = SensorPoses(dir / "poses_sptam.txt", Tr, 6);
    return k;
}

}  // namespace strata::registration::test
