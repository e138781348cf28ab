#include <bzlib.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "ScanBuilder.hpp"
#include "TextParsing.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::io {
namespace {

struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};

std::string Bzip2Error(int code) {
    switch (code) {
        case BZ_DATA_ERROR_MAGIC:
            return "not bzip2 data (bad magic)";
        case BZ_DATA_ERROR:
            return "corrupt bzip2 data";
        case BZ_UNEXPECTED_EOF:
            return "truncated bzip2 data";
        case BZ_MEM_ERROR:
            return "out of memory while decompressing";
        case BZ_IO_ERROR:
            return "read error";
        default:
            return "bzip2 error " + std::to_string(code);
    }
}

// bzip2 expands repetitive input 10^4 times and more, so a 66 kB file asked for 2 GB of text
// (found with fuzz_text_bz2). Point-cloud text compresses about 3x (the octomap example scan:
// 2.9x), so output beyond 1000x the file (and beyond 64 MiB, for tiny files) is refused.
constexpr uint64_t kMaxBzip2Ratio = 1000;
constexpr uint64_t kMinBzip2Limit = uint64_t{64} << 20;

// Decompresses a .bz2 file, including files made of several concatenated bzip2 streams.
std::string ReadBzip2File(const std::filesystem::path& path) {
    const std::string file = path.string();
    std::unique_ptr<std::FILE, FileCloser> f(std::fopen(file.c_str(), "rb"));
    if (!f) detail::FailOpen(path);
    std::error_code ec;
    const uint64_t compressed = std::filesystem::file_size(path, ec);
    const uint64_t limit = std::max(kMinBzip2Limit, kMaxBzip2Ratio * (ec ? 0 : compressed));
    std::string text;
    std::vector<char> unused;  // bytes read past the end of one stream: the next stream's start
    std::vector<char> chunk(1 << 16);
    for (;;) {
        int error = BZ_OK;
        BZFILE* bz =
            BZ2_bzReadOpen(&error, f.get(), 0, 0, unused.data(), static_cast<int>(unused.size()));
        if (error != BZ_OK) {
            BZ2_bzReadClose(&error, bz);
            throw IoError(file + ": cannot start bzip2 decompression");
        }
        while (error == BZ_OK) {
            const int n = BZ2_bzRead(&error, bz, chunk.data(), static_cast<int>(chunk.size()));
            if (error == BZ_OK || error == BZ_STREAM_END) text.append(chunk.data(), n);
            if (text.size() > limit) {
                BZ2_bzReadClose(&error, bz);
                throw FormatError(file + ": decompresses to more than " + std::to_string(limit) +
                                  " bytes (" + std::to_string(kMaxBzip2Ratio) +
                                  " times the file, at least 64 MiB): not point-cloud text");
            }
        }
        if (error != BZ_STREAM_END) {
            int ignored = BZ_OK;
            BZ2_bzReadClose(&ignored, bz);
            throw FormatError(file + ": " + Bzip2Error(error) + " after " +
                              std::to_string(text.size()) + " decompressed bytes");
        }
        void* rest = nullptr;
        int rest_size = 0;
        BZ2_bzReadGetUnused(&error, bz, &rest, &rest_size);
        const char* rest_bytes = static_cast<const char*>(rest);
        unused.assign(rest_bytes, rest_bytes + rest_size);  // copy before the close frees it
        BZ2_bzReadClose(&error, bz);
        if (unused.empty() && std::feof(f.get())) break;
        if (unused.empty()) {
            const int ch = std::fgetc(f.get());
            if (ch == EOF) break;
            unused.push_back(static_cast<char>(ch));
        }
    }
    return text;
}

bool EndsWith(const std::string& s, std::string_view suffix) {
    return s.size() >= suffix.size() &&
           s.compare(s.size() - suffix.size(), suffix.size(), suffix.data(), suffix.size()) == 0;
}

}  // namespace

core::Scan ReadText(const std::filesystem::path& path, const ReadOptions& options) {
    const std::string file = path.string();
    const bool bzip2 = EndsWith(file, ".bz2") || EndsWith(file, ".BZ2");
    const std::string text = bzip2 ? ReadBzip2File(path) : detail::ReadTextFile(path);

    detail::LineReader lines(text);
    std::vector<std::string_view> fields;
    std::string_view line;
    size_t columns = 0;  // fixed by the first data line: 3 (x y z) or 4 (x y z label)
    std::unique_ptr<detail::ScanBuilder> builder;
    while (lines.Next(line)) {
        detail::SplitFields(detail::StripComment(line), fields);
        if (fields.empty()) continue;
        auto fail = [&](const std::string& what) {
            throw FormatError(file + ": line " + std::to_string(lines.line_number()) + ": " + what);
        };
        if (columns == 0) {
            if (fields.size() != 3 && fields.size() != 4) {
                fail("expected `x y z [label]`, found " + std::to_string(fields.size()) +
                     " values");
            }
            columns = fields.size();
            builder = std::make_unique<detail::ScanBuilder>(
                path, options, detail::KittiMapping(),
                detail::PointLayout{false, columns == 4, false});
            builder->Reserve(text.size() / 32);  // a typical line is 20-40 bytes
        } else if (fields.size() != columns) {
            fail(std::to_string(fields.size()) + " values, but earlier lines have " +
                 std::to_string(columns));
        }
        double xyz[3] = {0.0, 0.0, 0.0};
        for (int k = 0; k < 3; ++k) {
            if (!detail::ParseDouble(fields[k], xyz[k])) {
                fail("cannot parse '" + std::string(fields[k].substr(0, 40)) + "' as a number");
            }
        }
        unsigned long long label = 0;
        if (columns == 4 && (!detail::ParseUint(fields[3], label) || label > 0xFFFFFFFFull)) {
            fail("label '" + std::string(fields[3].substr(0, 40)) + "' is not a 32-bit integer");
        }
        builder->Add(xyz[0], xyz[1], xyz[2], 0.f, static_cast<uint32_t>(label));
    }
    if (!builder) {  // no data lines: an empty scan, not an error
        core::Scan scan;
        scan.source = file;
        return scan;
    }
    return builder->Finish();
}

}  // namespace strata::io
