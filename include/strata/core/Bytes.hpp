#pragma once
// What processes of one job send each other (docs/scale.md): plain values (no pointers) and
// vectors of them, in the byte order and layout of the machines of one job (mpirun starts the
// same binary on each). Not a file format: nothing written with it outlives the job.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "strata/core/Error.hpp"

namespace strata::core {

template <typename T>
void Put(std::string& out, const T& value) {
    static_assert(std::is_trivially_copyable_v<T>, "plain values only");
    out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
void PutVector(std::string& out, const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>, "plain values only");
    Put(out, static_cast<uint64_t>(values.size()));
    out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

/// @brief Bytes of another encoding, with their length.
inline void PutBytes(std::string& out, const std::string& bytes) {
    Put(out, static_cast<uint64_t>(bytes.size()));
    out += bytes;
}

/// @brief Reads what Put, PutVector and PutBytes wrote, in the same order.
class ByteReader {
public:
    /// @param what names the answer in errors ("walls: a rank's answer is cut short").
    ByteReader(const std::string& bytes, std::string what)
        : bytes_(bytes), what_(std::move(what)) {}
    template <typename T>
    T Get() {
        T value;
        Take(&value, sizeof(T));
        return value;
    }
    template <typename T>
    std::vector<T> GetVector() {
        const auto n = Get<uint64_t>();
        if (n > (bytes_.size() - at_) / std::max<size_t>(1, sizeof(T))) Fail();
        std::vector<T> values(n);
        Take(values.data(), values.size() * sizeof(T));
        return values;
    }
    std::string GetBytes() {
        const auto n = Get<uint64_t>();
        if (n > bytes_.size() - at_) Fail();
        std::string bytes = bytes_.substr(at_, n);
        at_ += n;
        return bytes;
    }
    [[nodiscard]] std::string Rest() const { return bytes_.substr(at_); }

private:
    void Take(void* to, size_t n) {
        if (n > bytes_.size() - at_) Fail();
        if (n > 0) std::memcpy(to, bytes_.data() + at_, n);
        at_ += n;
    }
    [[noreturn]] void Fail() const { throw FormatError(what_ + ": a rank's answer is cut short"); }
    const std::string& bytes_;
    std::string what_;
    size_t at_ = 0;
};

}  // namespace strata::core
