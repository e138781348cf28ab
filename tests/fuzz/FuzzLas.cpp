// LAS 1.0-1.4: the header alone (what `strata info` style callers use) and the whole file.
#include "FuzzSupport.hpp"
#include "strata/io/PointCloudReaders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace strata;  // NOLINT(google-build-using-namespace): harness
    const auto path = fuzz::WriteInput(data, size, "cloud.las");
    fuzz::Refusal([&] { (void)io::ReadLasHeader(path); });
    fuzz::Refusal([&] { fuzz::ExpectValidScan(io::ReadPointCloud(path), true); });
    return 0;
}
