#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>

#include "strata/core/Labels.hpp"
#include "strata/core/Scan.hpp"

namespace strata::io {

/// @brief How a point cloud file is turned into a Scan.
struct ReadOptions {
    /// Subtracted from every coordinate in double precision (georeferenced data, e.g. LAS in UTM).
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();
    /// nullptr: the format's default (SemanticKITTI ids for PCD/PLY/text, LAS classes for LAS).
    const core::LabelMapping* mapping = nullptr;
    /// float32 values per point of a raw `.bin` scan: 4 (KITTI: x y z intensity), 5 (nuScenes:
    /// x y z intensity ring) or 0: 5 for names ending in `.pcd.bin`, else from the file size
    /// when exactly one of 4 and 5 divides it (ReadBin refuses the file when both or neither do).
    int bin_fields = 0;
};

/// @brief The file's extension in lower case, dot included ("scan.PCD" -> ".pcd", "" without
/// one): how the readers and exporters choose a format.
[[nodiscard]] std::string LowerExtension(const std::filesystem::path& path);

/// @brief Reads a point cloud chosen by extension: .pcd, .ply, .las, raw float32 .bin (KITTI,
/// nuScenes .pcd.bin), text (.txt .xyz .csv .dat) and bzip2-compressed text (any name ending in
/// .bz2).
/// @return a Scan at the identity pose, `time_s` 0 and `source` = path. Points are in the file's
/// frame minus `options.origin`. Non-finite points are dropped (PCD also drops (0,0,0), which
/// organised clouds use for missing returns).
/// @note Raw label ids follow SemanticKITTI's packing: the low 16 bits are the class (mapped to
/// `labels`), the high 16 bits the instance (`instances` is filled only when one is non-zero).
/// @throws InvalidArgumentError for an unknown extension; NotFoundError/IoError naming the file
/// when it cannot be read; FormatError naming it for .laz (with a hint to decompress it) and any
/// truncated or inconsistent file.
[[nodiscard]] core::Scan ReadPointCloud(const std::filesystem::path& path,
                                        const ReadOptions& options = {});

/// @brief PCD v0.7 with DATA ascii, binary or binary_compressed (LZF), any field order and types.
/// Uses x y z, optional `intensity` and optional `label`; other fields are skipped.
[[nodiscard]] core::Scan ReadPcd(const std::filesystem::path& path,
                                 const ReadOptions& options = {});

/// @brief PLY (ascii, binary_little_endian, binary_big_endian). Uses the `vertex` element's x y z,
/// optional label (`label`, `class`, `classification`) and intensity (`intensity`,
/// `scalar_intensity`, `reflectance`); other elements and properties, lists included, are skipped.
[[nodiscard]] core::Scan ReadPly(const std::filesystem::path& path,
                                 const ReadOptions& options = {});

/// @brief Raw little-endian float32 records, `options.bin_fields` per point (see ReadOptions):
/// x y z intensity [ring]; the ring is skipped. An empty file is a scan without points.
/// @throws InvalidArgumentError for a field count other than 0, 4 or 5; FormatError naming the
/// file when its size is not a whole number of records, or fits both counts and none was given.
[[nodiscard]] core::Scan ReadBin(const std::filesystem::path& path,
                                 const ReadOptions& options = {});

/// @brief Uncompressed LAS 1.0-1.4, point formats 0-10. Labels are the classification codes
/// (formats 0-5: the low 5 bits), intensity the 16-bit intensity.
[[nodiscard]] core::Scan ReadLas(const std::filesystem::path& path,
                                 const ReadOptions& options = {});

/// @brief Text with `x y z [label]` per line, separated by whitespace or commas; `#` starts a
/// comment. Files ending in .bz2 are decompressed with libbz2. Every line must have the same
/// number of values (3 or 4); a bad line is reported with its line number.
[[nodiscard]] core::Scan ReadText(const std::filesystem::path& path,
                                  const ReadOptions& options = {});

/// @brief The fields of a LAS public header block that readers need.
struct LasHeader {
    uint8_t version_major = 0;
    uint8_t version_minor = 0;
    uint8_t point_format = 0;        ///< without the compression bits
    bool compressed = false;         ///< LAZ: point format had bit 7 (or 6) set
    uint16_t header_size = 0;        ///< bytes
    uint32_t point_data_offset = 0;  ///< bytes from the start of the file
    uint16_t point_record_length = 0;
    uint64_t point_count = 0;  ///< the 64-bit count of LAS 1.4 when it is set
    Eigen::Vector3d scale = Eigen::Vector3d::Ones();
    Eigen::Vector3d offset = Eigen::Vector3d::Zero();
    Eigen::Vector3d min = Eigen::Vector3d::Zero();  ///< as the header states it, file units
    Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

/// @brief Reads and checks a LAS header (signature, sizes, point format) without reading points.
/// @throws FormatError naming the file when the header is invalid or disagrees with the
/// file size. A compressed (LAZ) header is returned with `compressed` set, not refused.
[[nodiscard]] LasHeader ReadLasHeader(const std::filesystem::path& path);

}  // namespace strata::io
