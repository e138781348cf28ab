// Plain text point clouds (`x y z [label]` per line).
#include "FuzzSupport.hpp"
#include "strata/io/PointCloudReaders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace strata;  // NOLINT(google-build-using-namespace): harness
    const auto path = fuzz::WriteInput(data, size, "cloud.txt");
    fuzz::Refusal([&] { fuzz::ExpectValidScan(io::ReadPointCloud(path), true); });
    return 0;
}
