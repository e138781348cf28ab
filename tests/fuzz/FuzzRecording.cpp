// Recordings (src/recordings/), ROS 1 bags, MCAP files and rosbag2 .db3 files by their first
// bytes: the container (its index or summary, or a scan of its records when it has none; every
// chunk compression; SQLite's tables), every message decoded by its type, and the sweeps posed
// and deskewed as `strata integrate --bag` reads them.
#include "FuzzSupport.hpp"
#include "strata/recordings/Messages.hpp"
#include "strata/recordings/RecordedScans.hpp"
#include "strata/recordings/Recording.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace strata;              // NOLINT(google-build-using-namespace): harness
    using namespace strata::recordings;  // NOLINT(google-build-using-namespace)
    const auto path = fuzz::WriteInput(data, size, "recording");
    const std::string file = path.string();
    fuzz::Refusal([&] {
        const auto bag = Recording::Open(path);
        bag->Read({}, [&](const Message& m) {
            fuzz::Refusal([&] {
                if (IsType(*m.topic, "sensor_msgs/PointCloud2")) {
                    const PointCloud c = DecodePointCloud2(m, file);
                    fuzz::Expect(c.intensity.empty() || c.intensity.size() == c.points.size(),
                                 "intensity per point");
                    fuzz::Expect(c.time_ns.empty() || c.time_ns.size() == c.points.size(),
                                 "a time per point");
                } else if (IsType(*m.topic, "tf2_msgs/TFMessage")) {
                    (void)DecodeTfMessage(m, file);
                } else if (IsType(*m.topic, "nav_msgs/Odometry")) {
                    (void)DecodeOdometry(m, file);
                } else if (IsType(*m.topic, "sensor_msgs/Imu")) {
                    (void)DecodeImu(m, file);
                }
            });
        });
    });
    // Posed by the tf tree and deskewed; and unposed for the odometry, with its IMU's readings.
    RecordedScanOptions unposed;
    unposed.posed = false;
    for (const RecordedScanOptions& options : {RecordedScanOptions{}, unposed}) {
        fuzz::Refusal([&] {
            const RecordedScans scans = RecordedScans::Open(path, options);
            for (size_t i = 0; i < scans.size(); ++i) {
                fuzz::Refusal([&] { fuzz::ExpectValidScan(scans.Read(i), true); });
            }
        });
    }
    return 0;
}
