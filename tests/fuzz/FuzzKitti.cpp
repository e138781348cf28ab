// KITTI velodyne .bin scans and SemanticKITTI .label files: the same bytes go to both readers.
// Both keep every record (NaN points included) so that scans and labels stay one-to-one.
#include "FuzzSupport.hpp"
#include "strata/io/KittiSequence.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace strata;  // NOLINT(google-build-using-namespace): harness
    const auto bin = fuzz::WriteInput(data, size, "000000.bin");
    fuzz::Refusal([&] {
        const io::KittiPoints scan = io::ReadKittiBin(bin);
        fuzz::Expect(scan.points.size() * 16 == size && scan.intensity.size() == scan.points.size(),
                     "a .bin scan that is not one point per 16 bytes");
    });
    const auto label = fuzz::WriteInput(data, size, "000000.label");
    fuzz::Refusal([&] {
        fuzz::Expect(io::ReadKittiLabels(label).size() * 4 == size,
                     "a .label file that is not one label per 4 bytes");
    });
    return 0;
}
