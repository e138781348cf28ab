#include <algorithm>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "BinaryCursor.hpp"
#include "PlyHeader.hpp"
#include "ScanBuilder.hpp"
#include "TextParsing.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::io {
namespace {

using detail::PlyElement;
using detail::PlyFormat;
using detail::ScalarType;

// Yields the body's values one at a time: binary through the bounds-checked cursor (either byte
// order), ascii as whitespace-separated tokens (one element item per line by convention, but
// only the token order matters).
class PlyValues {
public:
    PlyValues(std::string_view text, size_t data_offset, PlyFormat format, size_t header_lines,
              const std::string& file)
        : cursor_(reinterpret_cast<const uint8_t*>(text.data()), text.size(), file),
          text_(text),
          format_(format),
          line_(header_lines + 1) {
        cursor_.Seek(data_offset, "PLY data");
        pos_ = data_offset;
    }

    [[nodiscard]] bool ascii() const { return format_ == PlyFormat::kAscii; }
    [[nodiscard]] size_t remaining() const {
        return ascii() ? text_.size() - pos_ : cursor_.remaining();
    }

    double Next(ScalarType type) {
        if (!ascii()) {
            const uint8_t* p = cursor_.Take(detail::ScalarSize(type), "a PLY value");
            return detail::LoadAsDouble(p, type, format_ == PlyFormat::kBinaryBigEndian);
        }
        constexpr std::string_view kSpace = " \t\r\n";
        while (pos_ < text_.size() && kSpace.find(text_[pos_]) != std::string_view::npos) {
            if (text_[pos_++] == '\n') ++line_;
        }
        if (pos_ == text_.size()) cursor_.Fail("truncated: the ascii data ends early");
        const size_t end = std::min(text_.find_first_of(kSpace, pos_), text_.size());
        const std::string_view token = text_.substr(pos_, end - pos_);
        pos_ = end;
        double value = 0.0;
        if (!detail::ParseDouble(token, value)) {
            cursor_.Fail("line " + std::to_string(line_) + ": cannot parse '" +
                         std::string(token.substr(0, 40)) + "'");
        }
        return value;
    }

    // Reads a list length and skips its items; a length that cannot fit in the rest of the file
    // is reported before anything is skipped.
    void SkipList(ScalarType count_type, ScalarType item_type) {
        const double n = Next(count_type);
        const size_t max_items =
            ascii() ? remaining() : remaining() / detail::ScalarSize(item_type);
        if (!(n >= 0.0) || n > static_cast<double>(max_items)) {
            cursor_.Fail("truncated: a list of " + std::to_string(n) +
                         " items does not fit in the remaining " + std::to_string(remaining()) +
                         " bytes");
        }
        const auto items = static_cast<size_t>(n);
        if (!ascii()) {
            cursor_.Skip(items * detail::ScalarSize(item_type), "list items");
        } else {
            for (size_t i = 0; i < items; ++i) static_cast<void>(Next(item_type));
        }
    }

    // Skips all items of an element that is not the vertex element.
    void SkipElement(const PlyElement& element) {
        // Items without properties take no bytes, so there is nothing to skip whatever the
        // count: looping over a count of 10^14 empty items never ends (found by fuzz_ply).
        if (element.properties.empty()) return;
        if (!ascii() && !element.HasLists()) {
            const size_t size = element.MinBinarySize();
            if (size > 0 && element.count > cursor_.remaining() / size) {
                cursor_.Fail("truncated: element '" + element.name + "' needs " +
                             std::to_string(element.count) + " items of " + std::to_string(size) +
                             " bytes");
            }
            cursor_.Skip(static_cast<size_t>(element.count) * size, "element data");
            return;
        }
        for (uint64_t i = 0; i < element.count; ++i) {
            for (const auto& p : element.properties) {
                if (p.is_list) {
                    SkipList(p.count_type, p.type);
                } else {
                    static_cast<void>(Next(p.type));
                }
            }
        }
    }

private:
    detail::BinaryCursor cursor_;
    std::string_view text_;
    PlyFormat format_;
    size_t pos_ = 0;  // ascii read position
    size_t line_;
};

// Reads the vertex element into a Scan. Roles of its properties: 0-2 x y z, 3 intensity,
// 4 label, -1 skipped.
core::Scan ReadVertices(PlyValues& values, const PlyElement& element,
                        const std::filesystem::path& path, const ReadOptions& options) {
    const int x = element.Find({"x"}), y = element.Find({"y"}), z = element.Find({"z"});
    const int intensity = element.Find({"intensity", "scalar_intensity", "reflectance"});
    const int label = element.Find({"label", "class", "classification"});
    if (x < 0 || y < 0 || z < 0) {
        throw FormatError(path.string() + ": the vertex element has no x, y and z");
    }
    std::vector<int> role(element.properties.size(), -1);
    const int roles[5] = {x, y, z, intensity, label};
    for (int r = 0; r < 5; ++r) {
        if (roles[r] >= 0) role[static_cast<size_t>(roles[r])] = r;
    }
    detail::ScanBuilder builder(path, options, detail::KittiMapping(),
                                {intensity >= 0, label >= 0, /*drop_zero=*/false});
    // Never reserve more than the bytes left could hold.
    const size_t min_item = values.ascii() ? 2 * element.properties.size()
                                           : std::max<size_t>(1, element.MinBinarySize());
    builder.Reserve(
        static_cast<size_t>(std::min<uint64_t>(element.count, values.remaining() / min_item)));
    double v[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
    for (uint64_t i = 0; i < element.count; ++i) {
        for (size_t k = 0; k < element.properties.size(); ++k) {
            const auto& p = element.properties[k];
            if (p.is_list) {
                values.SkipList(p.count_type, p.type);
            } else if (role[k] >= 0) {
                v[role[k]] = values.Next(p.type);
            } else {
                static_cast<void>(values.Next(p.type));
            }
        }
        builder.Add(v[0], v[1], v[2], static_cast<float>(v[3]), detail::ToRawLabel(v[4]));
    }
    return builder.Finish();
}

}  // namespace

core::Scan ReadPly(const std::filesystem::path& path, const ReadOptions& options) {
    const std::string file = path.string();
    const std::vector<uint8_t> bytes = detail::ReadFileBytes(path);
    const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    const detail::PlyHeader header = detail::ParsePlyHeader(text, file);
    PlyValues values(text, header.data_offset, header.format, header.header_lines, file);
    core::Scan scan;
    bool has_vertices = false;
    // Elements after the vertices (faces, edges) are skipped too, so a truncated file is
    // reported wherever it is cut.
    for (const PlyElement& element : header.elements) {
        if (element.name == "vertex" && !has_vertices) {
            scan = ReadVertices(values, element, path, options);
            has_vertices = true;
        } else {
            values.SkipElement(element);
        }
    }
    if (!has_vertices) throw FormatError(file + ": no vertex element");
    return scan;
}

}  // namespace strata::io
