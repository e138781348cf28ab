#pragma once
// What ranks send each other (docs/scale.md): plain values (no pointers) and vectors of them, in
// the byte order and layout of the machines of one job (mpirun starts the same binary on each).

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "strata/core/Error.hpp"

namespace strata::pipeline::detail {

template <typename T>
void Put(std::string& out, const T& value) {
    out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
void PutVector(std::string& out, const std::vector<T>& values) {
    Put(out, static_cast<uint64_t>(values.size()));
    out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

/// @brief Reads what Put and PutVector wrote, in the same order.
class Reader {
public:
    /// @param what names the answer in errors ("walls: a rank's answer is cut short").
    Reader(const std::string& bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}
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

}  // namespace strata::pipeline::detail
