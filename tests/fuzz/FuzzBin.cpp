// Raw float32 scans (.bin, .pcd.bin) through the extension dispatch. The first byte picks the
// file name and the --bin-fields option (0: inferred, 4, 5, or an invalid 3); the rest is the file.
#include "FuzzSupport.hpp"
#include "strata/io/PointCloudReaders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace strata;  // NOLINT(google-build-using-namespace): harness
    if (size == 0) return 0;
    constexpr int kFields[] = {0, 4, 5, 3};
    io::ReadOptions options;
    options.bin_fields = kFields[data[0] % 4];
    const char* name = (data[0] / 4) % 2 == 0 ? "scan.bin" : "scan.pcd.bin";
    const auto path = fuzz::WriteInput(data + 1, size - 1, name);
    fuzz::Refusal([&] {
        const core::Scan scan = io::ReadPointCloud(path, options);
        fuzz::ExpectValidScan(scan, true);
        fuzz::Expect(scan.intensity.size() == scan.points.size(), "one intensity per point");
        fuzz::Expect(scan.points.size() * 16 <= size - 1, "more points than records");
    });
    return 0;
}
