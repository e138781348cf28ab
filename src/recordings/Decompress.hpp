#pragma once
// Private to recordings: the chunk compressions of the containers. Each decompresses a whole chunk
// whose uncompressed size the container declares, and refuses data that is damaged or that
// decompresses to any other size.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace strata::recordings::detail {

/// @brief bzip2 (ROS 1 bags' "bz2").
void DecompressBz2(const uint8_t* data, size_t size, size_t expected, std::vector<uint8_t>& out,
                   const std::string& where);

/// @brief The LZ4 frame format (ROS 1 bags' "lz4", written by roslz4).
void DecompressLz4Frame(const uint8_t* data, size_t size, size_t expected,
                        std::vector<uint8_t>& out, const std::string& where);

}  // namespace strata::recordings::detail
