// PCD v0.7: ascii, binary and binary_compressed (LZF), through the extension dispatch.
#include "FuzzSupport.hpp"
#include "strata/io/PointCloudReaders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace strata;  // NOLINT(google-build-using-namespace): harness
    const auto path = fuzz::WriteInput(data, size, "cloud.pcd");
    fuzz::Refusal([&] { fuzz::ExpectValidScan(io::ReadPointCloud(path), true); });
    return 0;
}
