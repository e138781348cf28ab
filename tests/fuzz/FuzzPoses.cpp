// Pose files: KITTI (12 values a line), TUM (8), the format detection, calib.txt `Tr:` and
// times.txt, all on the same bytes. An accepted file must give finite rigid transforms.
#include <cmath>

#include "FuzzSupport.hpp"
#include "strata/io/PoseFiles.hpp"

namespace {

void ExpectRigid(const Eigen::Isometry3d& T) {
    strata::fuzz::Expect(T.matrix().allFinite(), "a non-finite pose");
    const Eigen::Matrix3d R = T.linear();
    strata::fuzz::Expect(
        (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-2 &&
            R.determinant() > 0.0,
        "a pose whose rotation is not a rotation");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace strata;  // NOLINT(google-build-using-namespace): harness
    const auto path = fuzz::WriteInput(data, size, "poses.txt");
    fuzz::Refusal([&] {
        for (const io::StampedPose& p : io::ReadPoseFile(path)) ExpectRigid(p.T);
    });
    fuzz::Refusal([&] {
        for (const Eigen::Isometry3d& T : io::ReadKittiPoses(path)) ExpectRigid(T);
    });
    fuzz::Refusal([&] {
        for (const io::StampedPose& p : io::ReadTumPoses(path)) {
            ExpectRigid(p.T);
            fuzz::Expect(std::isfinite(p.time_s), "a non-finite TUM timestamp");
        }
    });
    fuzz::Refusal([&] { ExpectRigid(io::ReadKittiCalibTr(path)); });
    fuzz::Refusal([&] {
        for (double t : io::ReadTimes(path)) fuzz::Expect(std::isfinite(t), "a non-finite time");
    });
    return 0;
}
