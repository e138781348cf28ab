#pragma once
// Bounds-checked decoding of binary data: every reader of a binary format (io's point clouds,
// recordings' bags and messages) reads bytes through ByteCursor, so no read can leave the buffer
// and every failure is a FormatError naming the file.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>

namespace strata::core {

/// @brief Numeric types of binary fields (PCD, PLY, PointCloud2, ...).
enum class ScalarType : uint8_t { kI8, kU8, kI16, kU16, kI32, kU32, kI64, kU64, kF32, kF64 };

[[nodiscard]] size_t ScalarSize(ScalarType type);

template <size_t N>
struct UintOfSize;
template <>
struct UintOfSize<1> {
    using type = uint8_t;
};
template <>
struct UintOfSize<2> {
    using type = uint16_t;
};
template <>
struct UintOfSize<4> {
    using type = uint32_t;
};
template <>
struct UintOfSize<8> {
    using type = uint64_t;
};

/// @brief Decodes an arithmetic T stored at `p` in the given byte order (host-independent).
template <typename T>
[[nodiscard]] T LoadScalar(const uint8_t* p, bool big_endian) {
    static_assert(std::is_arithmetic_v<T>);
    using U = typename UintOfSize<sizeof(T)>::type;
    U bits = 0;
    for (size_t i = 0; i < sizeof(T); ++i) {
        const size_t shift = 8 * (big_endian ? sizeof(T) - 1 - i : i);
        bits = static_cast<U>(bits | static_cast<U>(static_cast<U>(p[i]) << shift));
    }
    T value;
    std::memcpy(&value, &bits, sizeof(T));
    return value;
}

/// @brief Decodes a value of `type` at `p` as a double (64-bit integers lose precision past 2^53).
[[nodiscard]] double LoadAsDouble(const uint8_t* p, ScalarType type, bool big_endian);

/// @brief A bounds-checked read position in a byte buffer it does not own.
class ByteCursor {
public:
    /// `file` names the bytes in errors (a file, or a file and what part of it).
    ByteCursor(const uint8_t* data, size_t size, std::string file)
        : data_(data), size_(size), file_(std::move(file)) {}

    [[nodiscard]] size_t position() const { return pos_; }
    [[nodiscard]] size_t size() const { return size_; }
    [[nodiscard]] size_t remaining() const { return size_ - pos_; }
    [[nodiscard]] const std::string& file() const { return file_; }

    /// @brief Returns a pointer to the next n bytes and moves past them; throws when truncated.
    const uint8_t* Take(size_t n, const char* what) {
        if (n > remaining()) FailTruncated(n, what);
        const uint8_t* p = data_ + pos_;
        pos_ += n;
        return p;
    }
    void Skip(size_t n, const char* what) { static_cast<void>(Take(n, what)); }
    void Seek(size_t pos, const char* what);

    template <typename T>
    [[nodiscard]] T Read(const char* what, bool big_endian = false) {
        return LoadScalar<T>(Take(sizeof(T), what), big_endian);
    }

    /// @brief Throws FormatError "<file>: <message>".
    [[noreturn]] void Fail(const std::string& message) const;

private:
    [[noreturn]] void FailTruncated(size_t n, const char* what) const;

    const uint8_t* data_;
    size_t size_;
    size_t pos_ = 0;
    std::string file_;
};

}  // namespace strata::core
