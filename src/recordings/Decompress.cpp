#include "Decompress.hpp"

#include <bzlib.h>
#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>
#include <zstd_errors.h>

#include <algorithm>
#include <limits>
#include <memory>

#include "FileReader.hpp"

namespace strata::recordings::detail {

void CheckDeclaredSize(size_t compressed, uint64_t declared, const std::string& where) {
    if (declared > (uint64_t{64} << 20) && declared / 2000 > compressed) {
        Fail(where, "a chunk of " + std::to_string(compressed) + " bytes declares " +
                        std::to_string(declared) + " uncompressed (damaged)");
    }
}

void DecompressBz2(const uint8_t* data, size_t size, size_t expected, std::vector<uint8_t>& out,
                   const std::string& where) {
    if (size > std::numeric_limits<unsigned>::max() ||
        expected > std::numeric_limits<unsigned>::max()) {
        Fail(where, "bz2 chunk of " + std::to_string(size) + " bytes is larger than bzip2 reads");
    }
    out.resize(expected + 1);  // one spare byte: data that decompresses to more is caught
    auto produced = static_cast<unsigned>(out.size());
    // bzlib takes non-const pointers but does not write through `source`.
    const int rc = BZ2_bzBuffToBuffDecompress(
        reinterpret_cast<char*>(out.data()), &produced,
        const_cast<char*>(reinterpret_cast<const char*>(data)), static_cast<unsigned>(size), 0, 0);
    if (rc == BZ_OUTBUFF_FULL || (rc == BZ_OK && produced != expected)) {
        Fail(where,
             "bz2 chunk decompresses to " +
                 (rc == BZ_OUTBUFF_FULL ? "more than" : std::to_string(produced) + " bytes, not") +
                 " the " + std::to_string(expected) + " bytes its header declares");
    }
    if (rc != BZ_OK) Fail(where, "damaged bz2 chunk (bzip2 error " + std::to_string(rc) + ")");
    out.resize(expected);
}

void DecompressLz4Frame(const uint8_t* data, size_t size, size_t expected,
                        std::vector<uint8_t>& out, const std::string& where) {
    LZ4F_dctx* raw = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) {
        throw std::bad_alloc();
    }
    const std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> dctx(
        raw, LZ4F_freeDecompressionContext);
    out.resize(expected + 1);  // as above
    size_t in_pos = 0, out_pos = 0, hint = 1;
    while (in_pos < size && hint != 0) {
        size_t in_n = size - in_pos, out_n = out.size() - out_pos;
        hint = LZ4F_decompress(dctx.get(), out.data() + out_pos, &out_n, data + in_pos, &in_n,
                               nullptr);
        if (LZ4F_isError(hint)) {
            Fail(where, std::string("damaged lz4 chunk: ") + LZ4F_getErrorName(hint));
        }
        in_pos += in_n;
        out_pos += out_n;
        if (in_n == 0 && out_n == 0) break;  // no progress: the output is full
    }
    if (hint != 0) {
        Fail(where, out_pos > expected ? "lz4 chunk decompresses to more than the " +
                                             std::to_string(expected) + " bytes its header declares"
                                       : "lz4 chunk ends inside its frame (truncated)");
    }
    if (out_pos != expected) {
        Fail(where, "lz4 chunk decompresses to " + std::to_string(out_pos) + " bytes, not the " +
                        std::to_string(expected) + " bytes its header declares");
    }
    out.resize(expected);
}

void DecompressZstd(const uint8_t* data, size_t size, size_t expected, std::vector<uint8_t>& out,
                    const std::string& where) {
    out.resize(expected);
    const size_t n = ZSTD_decompress(out.data(), out.size(), data, size);
    if (ZSTD_isError(n)) {
        if (ZSTD_getErrorCode(n) == ZSTD_error_dstSize_tooSmall) {
            Fail(where, "zstd chunk decompresses to more than the " + std::to_string(expected) +
                            " bytes its header declares");
        }
        Fail(where, std::string("damaged zstd chunk: ") + ZSTD_getErrorName(n));
    }
    if (n != expected) {
        Fail(where, "zstd chunk decompresses to " + std::to_string(n) + " bytes, not the " +
                        std::to_string(expected) + " bytes its header declares");
    }
}

bool IsZstdFrame(const uint8_t* data, size_t size) {
    static constexpr uint8_t kMagic[4] = {0x28, 0xB5, 0x2F, 0xFD};  // 0xFD2FB528, little-endian
    return size >= 4 && std::equal(kMagic, kMagic + 4, data);
}

void DecompressZstdFrame(const uint8_t* data, size_t size, std::vector<uint8_t>& out,
                         const std::string& where) {
    const unsigned long long declared = ZSTD_getFrameContentSize(data, size);
    if (declared == ZSTD_CONTENTSIZE_ERROR) Fail(where, "damaged zstd frame header");
    if (declared != ZSTD_CONTENTSIZE_UNKNOWN) {
        CheckDeclaredSize(size, declared, where);
        DecompressZstd(data, size, static_cast<size_t>(declared), out, where);
        return;
    }
    const size_t most = std::max<size_t>(size_t{1} << 20, size * 2000);
    const std::unique_ptr<ZSTD_DStream, size_t (*)(ZSTD_DStream*)> stream(ZSTD_createDStream(),
                                                                          ZSTD_freeDStream);
    if (!stream) Fail(where, "out of memory for zstd");
    ZSTD_inBuffer in{data, size, 0};
    out.resize(std::max<size_t>(size * 4, 4096));
    ZSTD_outBuffer dst{out.data(), out.size(), 0};
    for (;;) {
        const size_t left = ZSTD_decompressStream(stream.get(), &dst, &in);
        if (ZSTD_isError(left))
            Fail(where, std::string("damaged zstd frame: ") + ZSTD_getErrorName(left));
        if (left == 0) break;  // the frame's end
        if (in.pos == in.size && dst.pos < dst.size) Fail(where, "zstd frame cut short");
        if (dst.pos == dst.size) {
            if (out.size() >= most)
                Fail(where, "zstd frame decompresses to more than 2000x its size");
            out.resize(std::min(most, out.size() * 2));
            dst.dst = out.data();
            dst.size = out.size();
        }
    }
    out.resize(dst.pos);
}

uint32_t Crc32(const uint8_t* data, size_t size) {
    uLong crc = crc32(0L, Z_NULL, 0);
    while (size > 0) {  // zlib takes 32-bit lengths
        const auto n = static_cast<uInt>(std::min<size_t>(size, 1u << 30));
        crc = crc32(crc, data, n);
        data += n;
        size -= n;
    }
    return static_cast<uint32_t>(crc);
}

}  // namespace strata::recordings::detail
