#include "PcdHeader.hpp"

#include <vector>

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

namespace {

// The header's lines as written, before they are checked against each other.
struct RawPcdHeader {
    std::vector<std::string_view> fields, sizes, types, counts;
    bool has_points = false, has_width = false, has_data = false;
    unsigned long long width = 0, height = 1, points = 0;
    PcdEncoding encoding = PcdEncoding::kAscii;
};

PcdEncoding EncodingOf(std::string_view kind, const std::string& file, size_t line) {
    if (kind == "ascii") return PcdEncoding::kAscii;
    if (kind == "binary") return PcdEncoding::kBinary;
    if (kind == "binary_compressed") return PcdEncoding::kBinaryCompressed;
    FailHeader(file, line, "unknown DATA encoding '" + std::string(kind) + "'");
}

// Reads key lines up to and including DATA; `lines` is left at the first data byte.
RawPcdHeader ReadKeys(LineReader& lines, const std::string& file) {
    RawPcdHeader raw;
    std::vector<std::string_view> values;
    std::string_view line;
    while (!raw.has_data && lines.Next(line)) {
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
            raw.fields = values;
        } else if (key == "SIZE") {
            raw.sizes = values;
        } else if (key == "TYPE") {
            raw.types = values;
        } else if (key == "COUNT") {
            raw.counts = values;
        } else if (key == "WIDTH") {
            raw.width = number(kMaxDimension);
            raw.has_width = true;
        } else if (key == "HEIGHT") {
            raw.height = number(kMaxDimension);
        } else if (key == "POINTS") {
            raw.points = number(kMaxDimension * kMaxDimension);  // 2^62
            raw.has_points = true;
        } else if (key == "DATA") {
            raw.encoding = EncodingOf(values.empty() ? std::string_view() : values[0], file, n);
            raw.has_data = true;
        } else {
            FailHeader(file, n,
                       "unknown key '" + std::string(key.substr(0, 32)) + "' (not a PCD file?)");
        }
    }
    return raw;
}

// One PcdField per FIELDS entry, with its type, count and place in a binary record.
void LayOutFields(const RawPcdHeader& raw, PcdHeader& header, const std::string& file, size_t n) {
    const size_t num_fields = raw.fields.size();
    if (num_fields == 0) FailHeader(file, n, "no FIELDS");
    if (raw.sizes.size() != num_fields || raw.types.size() != num_fields ||
        (!raw.counts.empty() && raw.counts.size() != num_fields)) {
        FailHeader(file, n,
                   std::to_string(num_fields) + " FIELDS but " + std::to_string(raw.sizes.size()) +
                       " SIZE, " + std::to_string(raw.types.size()) + " TYPE and " +
                       std::to_string(raw.counts.size()) + " COUNT entries");
    }
    header.fields.assign(num_fields, PcdField{});
    for (size_t i = 0; i < num_fields; ++i) {
        PcdField& field = header.fields[i];
        field.name = std::string(raw.fields[i]);
        unsigned long long size = 0, count = 1;
        bool ok = ParseUint(raw.sizes[i], size);
        if (ok) field.type = ToScalarType(raw.types[i], size, ok);
        if (!ok) {
            FailHeader(file, n,
                       "field '" + field.name + "' has unsupported TYPE " +
                           std::string(raw.types[i]) + " with SIZE " + std::string(raw.sizes[i]));
        }
        if (!raw.counts.empty() &&
            (!ParseUint(raw.counts[i], count) || count == 0 || count > kMaxCount)) {
            FailHeader(
                file, n,
                "field '" + field.name + "' has invalid COUNT " + std::string(raw.counts[i]));
        }
        field.size = static_cast<size_t>(size);
        field.count = static_cast<size_t>(count);
        field.offset = header.record_size;
        field.column = header.values_per_point;
        header.record_size += field.size * field.count;
        header.values_per_point += field.count;
    }
}

}  // namespace

PcdHeader ParsePcdHeader(std::string_view text, const std::string& file) {
    LineReader lines(text);
    const RawPcdHeader raw = ReadKeys(lines, file);
    const size_t n = lines.line_number();
    if (!raw.has_data) {
        FailHeader(file, n, "no DATA line: not a PCD file, or the header is truncated");
    }
    PcdHeader header;
    header.encoding = raw.encoding;
    LayOutFields(raw, header, file, n);
    if (!raw.has_width) FailHeader(file, n, "no WIDTH");
    const unsigned long long points = raw.has_points ? raw.points : raw.width * raw.height;
    if (points != raw.width * raw.height) {
        FailHeader(file, n,
                   "POINTS " + std::to_string(points) + " disagrees with WIDTH * HEIGHT = " +
                       std::to_string(raw.width) + " * " + std::to_string(raw.height));
    }
    for (const char* axis : {"x", "y", "z"}) {
        if (header.Find(axis) < 0) FailHeader(file, n, std::string("no '") + axis + "' field");
    }
    header.width = static_cast<size_t>(raw.width);
    header.height = static_cast<size_t>(raw.height);
    header.points = static_cast<size_t>(points);
    header.data_offset = lines.position();
    header.header_lines = n;
    return header;
}

}  // namespace strata::io::detail
