#include "PcdHeader.hpp"

#include <stdexcept>

#include "TextParsing.hpp"

namespace strata::io::detail {
namespace {

// Bounds that no real header exceeds; they keep size arithmetic far from overflow.
constexpr unsigned long long kMaxDimension = 1ull << 31;
constexpr unsigned long long kMaxCount = 1ull << 20;

ScalarType ToScalarType(std::string_view type, unsigned long long size, bool& ok) {
    ok = true;
    if (type == "F" && size == 4) return ScalarType::kF32;
    if (type == "F" && size == 8) return ScalarType::kF64;
    if (type == "U" || type == "I") {
        const bool u = type == "U";
        if (size == 1) return u ? ScalarType::kU8 : ScalarType::kI8;
        if (size == 2) return u ? ScalarType::kU16 : ScalarType::kI16;
        if (size == 4) return u ? ScalarType::kU32 : ScalarType::kI32;
        if (size == 8) return u ? ScalarType::kU64 : ScalarType::kI64;
    }
    ok = false;
    return ScalarType::kU8;
}

}  // namespace

int PcdHeader::Find(std::string_view name) const {
    for (size_t i = 0; i < fields.size(); ++i) {
        if (fields[i].name == name) return static_cast<int>(i);
    }
    return -1;
}

PcdHeader ParsePcdHeader(std::string_view text, const std::string& file) {
    PcdHeader header;
    std::vector<std::string_view> sizes, types, counts, values;
    bool has_points = false, has_width = false, has_data = false;
    unsigned long long width = 0, height = 1, points = 0;
    LineReader lines(text);
    std::string_view line;
    while (!has_data && lines.Next(line)) {
        const size_t n = lines.line_number();
        SplitFields(StripComment(line), values);
        if (values.empty()) continue;
        const std::string_view key = values[0];
        values.erase(values.begin());
        auto number = [&](unsigned long long max) {
            unsigned long long v = 0;
            if (values.size() != 1 || !ParseUint(values[0], v) || v > max) {
                FailHeader(file, n,
                           std::string(key) + " needs one integer up to " + std::to_string(max));
            }
            return v;
        };
        if (key == "VERSION" || key == "VIEWPOINT") continue;
        if (key == "FIELDS") {
            header.fields.clear();
            for (std::string_view v : values) {
                PcdField field;
                field.name = std::string(v);
                header.fields.push_back(field);
            }
        } else if (key == "SIZE") {
            sizes = values;
        } else if (key == "TYPE") {
            types = values;
        } else if (key == "COUNT") {
            counts = values;
        } else if (key == "WIDTH") {
            width = number(kMaxDimension);
            has_width = true;
        } else if (key == "HEIGHT") {
            height = number(kMaxDimension);
        } else if (key == "POINTS") {
            points = number(kMaxDimension * kMaxDimension);  // 2^62
            has_points = true;
        } else if (key == "DATA") {
            const std::string_view kind = values.empty() ? std::string_view() : values[0];
            if (kind == "ascii") {
                header.encoding = PcdEncoding::kAscii;
            } else if (kind == "binary") {
                header.encoding = PcdEncoding::kBinary;
            } else if (kind == "binary_compressed") {
                header.encoding = PcdEncoding::kBinaryCompressed;
            } else {
                FailHeader(file, n, "unknown DATA encoding '" + std::string(kind) + "'");
            }
            has_data = true;
        } else {
            FailHeader(file, n,
                       "unknown key '" + std::string(key.substr(0, 32)) + "' (not a PCD file?)");
        }
    }
    const size_t n = lines.line_number();
    if (!has_data) FailHeader(file, n, "no DATA line: not a PCD file, or the header is truncated");
    const size_t num_fields = header.fields.size();
    if (num_fields == 0) FailHeader(file, n, "no FIELDS");
    if (sizes.size() != num_fields || types.size() != num_fields ||
        (!counts.empty() && counts.size() != num_fields)) {
        FailHeader(file, n,
             std::to_string(num_fields) + " FIELDS but " + std::to_string(sizes.size()) +
                 " SIZE, " + std::to_string(types.size()) + " TYPE and " +
                 std::to_string(counts.size()) + " COUNT entries");
    }
    for (size_t i = 0; i < num_fields; ++i) {
        PcdField& field = header.fields[i];
        unsigned long long size = 0, count = 1;
        bool ok = ParseUint(sizes[i], size);
        if (ok) field.type = ToScalarType(types[i], size, ok);
        if (!ok) {
            FailHeader(file, n,
                 "field '" + field.name + "' has unsupported TYPE " + std::string(types[i]) +
                     " with SIZE " + std::string(sizes[i]));
        }
        if (!counts.empty() && (!ParseUint(counts[i], count) || count == 0 || count > kMaxCount)) {
            FailHeader(file, n,
                       "field '" + field.name + "' has invalid COUNT " + std::string(counts[i]));
        }
        field.size = static_cast<size_t>(size);
        field.count = static_cast<size_t>(count);
        field.offset = header.record_size;
        field.column = header.values_per_point;
        header.record_size += field.size * field.count;
        header.values_per_point += field.count;
    }
    if (!has_width) FailHeader(file, n, "no WIDTH");
    if (!has_points) points = width * height;
    if (points != width * height) {
        FailHeader(file, n,
             "POINTS " + std::to_string(points) + " disagrees with WIDTH * HEIGHT = " +
                 std::to_string(width) + " * " + std::to_string(height));
    }
    for (const char* axis : {"x", "y", "z"}) {
        if (header.Find(axis) < 0) FailHeader(file, n, std::string("no '") + axis + "' field");
    }
    header.width = static_cast<size_t>(width);
    header.height = static_cast<size_t>(height);
    header.points = static_cast<size_t>(points);
    header.data_offset = lines.position();
    header.header_lines = n;
    return header;
}

}  // namespace strata::io::detail
