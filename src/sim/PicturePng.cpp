#include <stdexcept>

#include "strata/core/Error.hpp"
#include "strata/io/Image.hpp"
#include "strata/sim/ScenePicture.hpp"

namespace strata::sim {

void WritePicturePng(const std::filesystem::path& path, const Picture& picture) {
    if (picture.width <= 0 || picture.height <= 0 ||
        picture.rgb.size() != size_t(picture.width) * size_t(picture.height) * 3) {
        throw InvalidArgumentError("cannot write an empty or malformed picture to " +
                                   path.string());
    }
    io::RgbImage image(picture.width, picture.height);
    for (int y = 0; y < picture.height; ++y) {
        for (int x = 0; x < picture.width; ++x) {
            const uint8_t* px = &picture.rgb[(size_t(y) * size_t(picture.width) + size_t(x)) * 3];
            image.Set(x, y, {px[0], px[1], px[2]});
        }
    }
    io::WritePng(image, path);  // all or nothing, like every file strata writes
}

}  // namespace strata::sim
