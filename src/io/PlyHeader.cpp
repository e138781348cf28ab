#include "PlyHeader.hpp"

#include <stdexcept>

#include "TextParsing.hpp"
#include "strata/core/Error.hpp"

namespace strata::io::detail {
namespace {

bool ToScalarType(std::string_view name, ScalarType& type) {
    struct Entry {
        std::string_view a, b;
        ScalarType type;
    };
    static constexpr Entry kTypes[] = {
        {"char", "int8", ScalarType::kI8},      {"uchar", "uint8", ScalarType::kU8},
        {"short", "int16", ScalarType::kI16},   {"ushort", "uint16", ScalarType::kU16},
        {"int", "int32", ScalarType::kI32},     {"uint", "uint32", ScalarType::kU32},
        {"float", "float32", ScalarType::kF32}, {"double", "float64", ScalarType::kF64},
        {"int64", "long", ScalarType::kI64},    {"uint64", "ulong", ScalarType::kU64},
    };
    for (const Entry& e : kTypes) {
        if (name == e.a || name == e.b) {
            type = e.type;
            return true;
        }
    }
    return false;
}

}  // namespace

size_t PlyElement::MinBinarySize() const {
    size_t size = 0;
    for (const PlyProperty& p : properties) size += ScalarSize(p.is_list ? p.count_type : p.type);
    return size;
}

bool PlyElement::HasLists() const {
    for (const PlyProperty& p : properties) {
        if (p.is_list) return true;
    }
    return false;
}

int PlyElement::Find(std::initializer_list<std::string_view> names) const {
    for (size_t i = 0; i < properties.size(); ++i) {
        for (std::string_view name : names) {
            if (!properties[i].is_list && properties[i].name == name) return static_cast<int>(i);
        }
    }
    return -1;
}

PlyHeader ParsePlyHeader(std::string_view text, const std::string& file) {
    PlyHeader header;
    LineReader lines(text);
    std::string_view line;
    if (!lines.Next(line) || line != "ply") {
        throw FormatError(file + ": not a PLY file (the first line is not 'ply')");
    }
    std::vector<std::string_view> words;
    bool has_format = false;
    while (lines.Next(line)) {
        const size_t n = lines.line_number();
        SplitFields(line, words);
        if (words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
        if (words[0] == "end_header") {
            if (!has_format) FailHeader(file, n, "no format line");
            header.data_offset = lines.position();
            header.header_lines = n;
            return header;
        }
        if (words[0] == "format" && words.size() >= 2) {
            if (words[1] == "ascii") {
                header.format = PlyFormat::kAscii;
            } else if (words[1] == "binary_little_endian") {
                header.format = PlyFormat::kBinaryLittleEndian;
            } else if (words[1] == "binary_big_endian") {
                header.format = PlyFormat::kBinaryBigEndian;
            } else {
                FailHeader(file, n, "unknown format '" + std::string(words[1]) + "'");
            }
            has_format = true;
        } else if (words[0] == "element" && words.size() == 3) {
            PlyElement element;
            element.name = std::string(words[1]);
            unsigned long long count = 0;
            if (!ParseUint(words[2], count)) {
                FailHeader(file, n, "bad element count '" + std::string(words[2]) + "'");
            }
            element.count = count;
            header.elements.push_back(element);
        } else if (words[0] == "property" && !header.elements.empty()) {
            PlyProperty property;
            bool ok = false;
            if (words.size() == 3) {
                ok = ToScalarType(words[1], property.type);
            } else if (words.size() == 5 && words[1] == "list") {
                property.is_list = true;
                ok = ToScalarType(words[2], property.count_type) &&
                     ToScalarType(words[3], property.type);
            }
            if (!ok) FailHeader(file, n, "bad property '" + std::string(line.substr(0, 80)) + "'");
            property.name = std::string(words.back());
            header.elements.back().properties.push_back(property);
        } else {
            FailHeader(file, n, "unexpected line '" + std::string(line.substr(0, 80)) + "'");
        }
    }
    throw FormatError(file + ": no end_header: the PLY header is truncated");
}

}  // namespace strata::io::detail
