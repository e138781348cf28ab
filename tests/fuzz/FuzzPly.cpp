// PLY: ascii, binary_little_endian and binary_big_endian, lists and extra elements included.
#include "FuzzSupport.hpp"
#include "strata/io/PointCloudReaders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace strata;  // NOLINT(google-build-using-namespace): harness
    const auto path = fuzz::WriteInput(data, size, "cloud.ply");
    fuzz::Refusal([&] { fuzz::ExpectValidScan(io::ReadPointCloud(path), true); });
    return 0;
}
