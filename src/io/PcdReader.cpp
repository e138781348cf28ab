#include <lzf.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "BinaryCursor.hpp"
#include "PcdHeader.hpp"
#include "ScanBuilder.hpp"
#include "TextParsing.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::io {
namespace {

using detail::PcdEncoding;
using detail::PcdHeader;

// LZF encodes at most 264 output bytes per 3-byte back-reference, so a claim beyond this ratio
// is corrupt; checking it bounds the allocation by the file size.
constexpr size_t kMaxLzfRatio = 90;

// Field indices of the attributes a Scan takes (-1 when absent).
struct PcdColumns {
    int x, y, z, intensity, label;
};

// Binary layouts: `Locate(i, f)` returns the first element of field f of point i.
// binary: records back to back; binary_compressed: all of field 0, then all of field 1, ...
// PCL writes host byte order, little-endian on every platform it ships binaries for.
template <typename Locate>
void ReadBinaryPoints(const PcdHeader& h, const PcdColumns& c, Locate locate,
                      detail::ScanBuilder& builder) {
    auto value = [&](size_t i, int f) {
        return detail::LoadAsDouble(locate(i, f), h.fields[static_cast<size_t>(f)].type, false);
    };
    for (size_t i = 0; i < h.points; ++i) {
        const float intensity = c.intensity >= 0 ? static_cast<float>(value(i, c.intensity)) : 0.f;
        const uint32_t label = c.label >= 0 ? detail::ToRawLabel(value(i, c.label)) : 0;
        builder.Add(value(i, c.x), value(i, c.y), value(i, c.z), intensity, label);
    }
}

void ReadAsciiPoints(std::string_view text, const PcdHeader& h, const PcdColumns& c,
                     const std::string& file, detail::ScanBuilder& builder) {
    detail::LineReader lines(text.substr(h.data_offset));
    std::vector<std::string_view> values;
    std::vector<double> row(h.values_per_point);
    std::string_view line;
    size_t read = 0;
    auto column = [&](int f) { return h.fields[static_cast<size_t>(f)].column; };
    while (read < h.points && lines.Next(line)) {
        detail::SplitFields(line, values);
        if (values.empty()) continue;
        const size_t line_number = h.header_lines + lines.line_number();
        if (values.size() != h.values_per_point) {
            throw FormatError(file + ": line " + std::to_string(line_number) + " has " +
                              std::to_string(values.size()) + " values, expected " +
                              std::to_string(h.values_per_point));
        }
        // Every value must parse, used or not: a bad token anywhere means a corrupt file.
        for (size_t k = 0; k < values.size(); ++k) {
            if (!detail::ParseDouble(values[k], row[k])) {
                throw FormatError(file + ": line " + std::to_string(line_number) +
                                  ": cannot parse '" + std::string(values[k].substr(0, 40)) + "'");
            }
        }
        auto get = [&](int f) { return f >= 0 ? row[column(f)] : 0.0; };
        const double v[5] = {get(c.x), get(c.y), get(c.z), get(c.intensity), get(c.label)};
        builder.Add(v[0], v[1], v[2], static_cast<float>(v[3]), detail::ToRawLabel(v[4]));
        ++read;
    }
    if (read < h.points) {
        throw FormatError(file + ": truncated: " + std::to_string(read) + " of " +
                          std::to_string(h.points) + " points in the ascii data");
    }
}

}  // namespace

core::Scan ReadPcd(const std::filesystem::path& path, const ReadOptions& options) {
    const std::string file = path.string();
    const std::vector<uint8_t> bytes = detail::ReadFileBytes(path);
    const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    const PcdHeader h = detail::ParsePcdHeader(text, file);
    const PcdColumns c{h.Find("x"), h.Find("y"), h.Find("z"), h.Find("intensity"), h.Find("label")};
    detail::ScanBuilder builder(path, options, detail::KittiMapping(),
                                {c.intensity >= 0, c.label >= 0, /*drop_zero=*/true});
    detail::BinaryCursor cursor(bytes.data(), bytes.size(), file);
    cursor.Seek(h.data_offset, "point data");
    auto offset = [&](int f) { return h.fields[static_cast<size_t>(f)].offset; };

    if (h.encoding == PcdEncoding::kAscii) {
        if (h.points > 0 && h.values_per_point > cursor.remaining()) {
            cursor.Fail("truncated: one ascii point has " + std::to_string(h.values_per_point) +
                        " values, but only " + std::to_string(cursor.remaining()) +
                        " bytes remain");
        }
        // An ascii point takes at least 2 bytes per value, which bounds the reservation.
        builder.Reserve(std::min(h.points, cursor.remaining() / (2 * h.values_per_point)));
        ReadAsciiPoints(text, h, c, file, builder);
    } else if (h.encoding == PcdEncoding::kBinary) {
        if (h.points > cursor.remaining() / h.record_size) {
            cursor.Fail("truncated: " + std::to_string(h.points) + " points of " +
                        std::to_string(h.record_size) + " bytes each, but only " +
                        std::to_string(cursor.remaining()) + " bytes of binary data remain");
        }
        const uint8_t* data = cursor.Take(h.points * h.record_size, "binary point data");
        builder.Reserve(h.points);
        ReadBinaryPoints(
            h, c, [&](size_t i, int f) { return data + i * h.record_size + offset(f); }, builder);
    } else {
        const size_t compressed = cursor.Read<uint32_t>("compressed size");
        const size_t uncompressed = cursor.Read<uint32_t>("uncompressed size");
        const uint8_t* lzf = cursor.Take(compressed, "LZF data");
        if (uncompressed > compressed * kMaxLzfRatio + 64) {
            cursor.Fail("compressed data claims " + std::to_string(uncompressed) + " bytes from " +
                        std::to_string(compressed) + " LZF bytes, more than LZF can encode");
        }
        if (uncompressed % h.record_size != 0 || uncompressed / h.record_size != h.points) {
            cursor.Fail("uncompressed size " + std::to_string(uncompressed) +
                        " disagrees with POINTS * record size = " + std::to_string(h.points) +
                        " * " + std::to_string(h.record_size));
        }
        std::vector<uint8_t> data(uncompressed);
        if (uncompressed > 0) {
            const unsigned int got =
                lzf_decompress(lzf, static_cast<unsigned int>(compressed), data.data(),
                               static_cast<unsigned int>(uncompressed));
            if (got != uncompressed) {
                cursor.Fail("LZF decompression failed (" + std::to_string(got) + " of " +
                            std::to_string(uncompressed) + " bytes): corrupt compressed data");
            }
        }
        builder.Reserve(h.points);
        ReadBinaryPoints(
            h, c,
            [&](size_t i, int f) {
                const auto& field = h.fields[static_cast<size_t>(f)];
                return data.data() + offset(f) * h.points + i * field.size * field.count;
            },
            builder);
    }
    return builder.Finish();
}

}  // namespace strata::io
