#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "BinaryCursor.hpp"
#include "ScanBuilder.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::io {
namespace {

// Offsets in the public header block (ASPRS LAS 1.4 R15, table 3; 1.0-1.3 share the first 227).
constexpr size_t kVersionAt = 24, kHeaderSizeAt = 94;  // the point format follows at 104
constexpr size_t kScaleAt = 131, kCount64At = 247;
constexpr size_t kMinHeaderSize = 227, kHeader14Size = 375;
// Minimum point record length of formats 0-10 (extra bytes may follow).
constexpr uint16_t kMinRecordLength[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

LasHeader ParseLasHeader(detail::BinaryCursor& c, size_t file_size) {
    if (std::string(reinterpret_cast<const char*>(c.Take(4, "LAS signature")), 4) != "LASF") {
        c.Fail("not a LAS file (no 'LASF' signature)");
    }
    LasHeader h;
    c.Seek(kVersionAt, "version");
    h.version_major = c.Read<uint8_t>("version");
    h.version_minor = c.Read<uint8_t>("version");
    if (h.version_major != 1 || h.version_minor > 4) {
        c.Fail("unsupported LAS version " + std::to_string(h.version_major) + "." +
               std::to_string(h.version_minor) + " (1.0-1.4 are read)");
    }
    c.Seek(kHeaderSizeAt, "header size");
    h.header_size = c.Read<uint16_t>("header size");
    h.point_data_offset = c.Read<uint32_t>("offset to point data");
    c.Skip(4, "number of VLRs");
    const uint8_t format = c.Read<uint8_t>("point data format");
    h.point_record_length = c.Read<uint16_t>("point record length");
    const uint32_t legacy_count = c.Read<uint32_t>("point count");
    // LASzip marks compressed data by setting bit 7 (bit 6 in early versions) of the format.
    h.compressed = (format & 0xC0) != 0;
    h.point_format = static_cast<uint8_t>(format & 0x3F);
    c.Seek(kScaleAt, "scale");
    for (int i = 0; i < 3; ++i) h.scale[i] = c.Read<double>("scale");
    for (int i = 0; i < 3; ++i) h.offset[i] = c.Read<double>("offset");
    for (int i = 0; i < 3; ++i) {  // stored as max x, min x, max y, min y, max z, min z
        h.max[i] = c.Read<double>("bounds");
        h.min[i] = c.Read<double>("bounds");
    }
    h.point_count = legacy_count;
    if (h.version_minor >= 4 && h.header_size >= kHeader14Size) {
        c.Seek(kCount64At, "64-bit point count");
        const auto count64 = c.Read<uint64_t>("64-bit point count");
        if (legacy_count != 0 && count64 != legacy_count) {
            c.Fail("legacy point count " + std::to_string(legacy_count) +
                   " disagrees with the 64-bit count " + std::to_string(count64));
        }
        h.point_count = count64;
    }
    if (h.header_size < kMinHeaderSize || h.point_data_offset < h.header_size ||
        h.point_data_offset > file_size) {
        c.Fail("inconsistent header: header size " + std::to_string(h.header_size) +
               ", point data at byte " + std::to_string(h.point_data_offset) + ", file size " +
               std::to_string(file_size));
    }
    if (h.point_format > 10 || h.point_record_length < kMinRecordLength[h.point_format]) {
        c.Fail("unsupported point format " + std::to_string(h.point_format) +
               " with record length " + std::to_string(h.point_record_length));
    }
    if (!h.scale.allFinite() || (h.scale.array() == 0.0).any() || !h.offset.allFinite()) {
        c.Fail("scale or offset is zero or not finite");
    }
    // Compressed records are smaller than point_record_length, so only LAS is checked here.
    const size_t available = file_size - h.point_data_offset;
    if (!h.compressed && h.point_count > available / h.point_record_length) {
        c.Fail("truncated: header announces " + std::to_string(h.point_count) + " points of " +
               std::to_string(h.point_record_length) + " bytes, but only " +
               std::to_string(available) + " bytes of point data follow");
    }
    return h;
}

[[noreturn]] void RefuseLaz(const std::string& file) {
    throw FormatError(file +
                      ": LAZ (compressed LAS) is not supported; decompress it first, e.g. "
                      "`pdal translate in.laz out.las` or `laszip -i in.laz -o out.las`");
}

}  // namespace

LasHeader ReadLasHeader(const std::filesystem::path& path) {
    size_t file_size = 0;
    const std::vector<uint8_t> bytes = detail::ReadFileBytes(path, kHeader14Size, &file_size);
    detail::BinaryCursor cursor(bytes.data(), bytes.size(), path.string());
    return ParseLasHeader(cursor, file_size);
}

core::Scan ReadLas(const std::filesystem::path& path, const ReadOptions& options) {
    const std::string file = path.string();
    if (LowerExtension(path) == ".laz") RefuseLaz(file);
    const std::vector<uint8_t> bytes = detail::ReadFileBytes(path);
    detail::BinaryCursor cursor(bytes.data(), bytes.size(), file);
    const LasHeader h = ParseLasHeader(cursor, bytes.size());
    if (h.compressed) RefuseLaz(file);

    // Formats 0-5 keep the class in the low 5 bits of byte 15; formats 6-10 use all of byte 16.
    const bool legacy = h.point_format <= 5;
    const size_t class_at = legacy ? 15 : 16;
    const uint8_t class_mask = legacy ? 0x1F : 0xFF;
    detail::ScanBuilder builder(path, options, detail::LasMapping(),
                                {/*has_intensity=*/true, /*has_label=*/true, /*drop_zero=*/false});
    builder.Reserve(static_cast<size_t>(h.point_count));  // checked against the file size
    cursor.Seek(h.point_data_offset, "point data");
    for (uint64_t i = 0; i < h.point_count; ++i) {
        const uint8_t* r = cursor.Take(h.point_record_length, "point record");
        const double x = detail::LoadScalar<int32_t>(r, false) * h.scale.x() + h.offset.x();
        const double y = detail::LoadScalar<int32_t>(r + 4, false) * h.scale.y() + h.offset.y();
        const double z = detail::LoadScalar<int32_t>(r + 8, false) * h.scale.z() + h.offset.z();
        const float intensity = detail::LoadScalar<uint16_t>(r + 12, false);
        builder.Add(x, y, z, intensity, r[class_at] & class_mask);
    }
    return builder.Finish();
}

}  // namespace strata::io
