// bzip2-compressed text point clouds: the decompressor (concatenated streams) and the parser.
#include "FuzzSupport.hpp"
#include "strata/io/PointCloudReaders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace strata;  // NOLINT(google-build-using-namespace): harness
    const auto path = fuzz::WriteInput(data, size, "scan.dat.bz2");
    fuzz::Refusal([&] { fuzz::ExpectValidScan(io::ReadPointCloud(path), true); });
    return 0;
}
