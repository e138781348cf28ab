#pragma once
// The simulator's district drive (strata::test::DistrictDrive) as a KITTI-layout folder without
// poses.txt: what `strata odometry` and `strata integrate --odometry` are given in the tests.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "SimulatedDrive.hpp"
#include "TempPath.hpp"
#include "strata/io/KittiSequence.hpp"

namespace strata::tools::test {

/// The drive's first `sweeps` sweeps as velodyne/NNNNNN.bin, no poses; `elsewhere`: that sweep's
/// points moved 300 m away.
inline std::filesystem::path WriteDriveFolder(const std::string& name, size_t sweeps,
                                              size_t elsewhere = SIZE_MAX) {
    const strata::test::SimulatedDrive& drive = strata::test::DistrictDrive(sweeps);
    const std::filesystem::path dir = strata::test::TempPath(name);
    std::filesystem::create_directories(dir / "velodyne");
    for (size_t k = 0; k < drive.sweeps.size(); ++k) {
        std::vector<Eigen::Vector3d> points = drive.sweeps[k];
        if (k == elsewhere) {
            for (Eigen::Vector3d& p : points) p.x() += 300.0;
        }
        char file[32];
        std::snprintf(file, sizeof(file), "%06zu.bin", k);
        io::WriteKittiBin(dir / "velodyne" / file, points);
    }
    return dir;
}

}  // namespace strata::tools::test
