#pragma once
// Private to recordings: the chunk compressions of the containers. Each decompresses a whole chunk
// whose uncompressed size the container declares, and refuses data that is damaged or that
// decompresses to any other size.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace strata::recordings::detail {

/// @brief Refuses a chunk whose declared uncompressed size no compressor reaches on sensor data
/// (above 64 MiB and 2000 times its compressed size): damage, caught before the memory is taken.
void CheckDeclaredSize(size_t compressed, uint64_t declared, const std::string& where);

/// @brief bzip2 (ROS 1 bags' "bz2").
void DecompressBz2(const uint8_t* data, size_t size, size_t expected, std::vector<uint8_t>& out,
                   const std::string& where);

/// @brief The LZ4 frame format (ROS 1 bags' "lz4", written by roslz4; MCAP's "lz4").
void DecompressLz4Frame(const uint8_t* data, size_t size, size_t expected,
                        std::vector<uint8_t>& out, const std::string& where);

/// @brief Zstandard (MCAP's "zstd").
void DecompressZstd(const uint8_t* data, size_t size, size_t expected, std::vector<uint8_t>& out,
                    const std::string& where);

/// @brief True when `data` begins with a Zstandard frame's magic number.
[[nodiscard]] bool IsZstdFrame(const uint8_t* data, size_t size);
/// @brief One Zstandard frame whose size only its header may tell (rosbag2 compresses each
/// message as one): to the size it declares (CheckDeclaredSize's refusals apply), or, for a frame
/// written as a stream without one, to its end, at most 2000 times its compressed size.
void DecompressZstdFrame(const uint8_t* data, size_t size, std::vector<uint8_t>& out,
                         const std::string& where);

/// @brief The CRC-32 (ISO-HDLC, as zlib computes it) of `size` bytes.
[[nodiscard]] uint32_t Crc32(const uint8_t* data, size_t size);

}  // namespace strata::recordings::detail
