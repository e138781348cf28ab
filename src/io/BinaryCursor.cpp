#include "BinaryCursor.hpp"

#include <algorithm>
#include <cerrno>
#include <fstream>

#include "TextParsing.hpp"
#include "strata/core/Error.hpp"

namespace strata::io::detail {

std::vector<uint8_t> ReadFileBytes(const std::filesystem::path& path, size_t max_bytes,
                                   size_t* file_size) {
    RequireFile(path);
    errno = 0;
    std::ifstream in(path, std::ios::binary);
    if (!in) FailOpen(path);
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) throw IoError(path.string() + ": cannot determine the file size");
    in.seekg(0, std::ios::beg);
    if (file_size != nullptr) *file_size = static_cast<size_t>(size);
    const size_t wanted = std::min(static_cast<size_t>(size), max_bytes);
    std::vector<uint8_t> bytes(wanted);
    if (wanted > 0 &&
        !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(wanted))) {
        throw IoError(path.string() + ": read error after " + std::to_string(in.gcount()) + " of " +
                      std::to_string(wanted) + " bytes");
    }
    return bytes;
}

}  // namespace strata::io::detail
