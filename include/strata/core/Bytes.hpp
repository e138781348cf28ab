#pragma once
// What processes of one job send each other (docs/scale.md): plain values (no pointers), fixed-size
// Eigen vectors, pairs and vectors of them, and records whose fields are named once in a
// `Fields` specialisation, in the byte order and layout of the machines of one job (mpirun
// starts the same binary on each). Not a file format: nothing written with it outlives the job.

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "strata/core/Error.hpp"

namespace strata::core {

/// @brief Names the fields of a record sent between processes, once for both directions. A
/// record that holds more than plain values (Eigen vectors, std::vectors, other records)
/// specialises it beside its encoder, in namespace strata::core and before its first Put or Get:
/// @code
/// template <> struct Fields<walls::Wall> {
///     template <typename Io, typename W>  // W: const walls::Wall to write, walls::Wall to read
///     static void Visit(Io& io, W& w) { io(w.centroid, w.normal, w.voxels); }
/// };
/// @endcode
/// Put writes the fields in that order and ByteReader::Get reads them back the same way, so an
/// encoder and its decoder cannot disagree.
template <typename T>
struct Fields;

////////////////////////////////////////

namespace detail {

template <typename T, typename = void>
struct HasFields : std::false_type {};
template <typename T>
struct HasFields<T, std::void_t<decltype(sizeof(Fields<T>))>> : std::true_type {};

template <typename T>
struct IsPair : std::false_type {};
template <typename A, typename B>
struct IsPair<std::pair<A, B>> : std::true_type {};

template <typename T>
struct IsVector : std::false_type {};
template <typename T>
struct IsVector<std::vector<T>> : std::true_type {};

// Eigen's fixed-size matrices and vectors (their size known at compile time): the members are
// looked up first, so that no other type makes Eigen instantiate anything.
template <typename T, typename = void>
struct IsFixedEigen : std::false_type {};
template <typename T>
struct IsFixedEigen<T, std::void_t<typename T::Scalar, decltype(T::SizeAtCompileTime)>>
    : std::bool_constant<std::is_base_of_v<Eigen::MatrixBase<T>, T> && (T::SizeAtCompileTime > 0)> {
};

/// A value copied as its bytes: trivially copyable, and neither a record, an Eigen matrix nor a
/// pair.
template <typename T>
inline constexpr bool kPlain = !HasFields<T>::value && !IsFixedEigen<T>::value &&
                               !IsPair<T>::value && std::is_trivially_copyable_v<T>;

}  // namespace detail

/// @brief Appends `value` to `out`: a plain value as its bytes, an Eigen vector by its
/// coefficients, a pair as its two members, a vector as its length and its elements, a record
/// by its Fields.
template <typename T>
void Put(std::string& out, const T& value);

namespace detail {

/// What Fields<T>::Visit calls when a record is written.
struct FieldWriter {
    std::string& out;
    template <typename... T>
    void operator()(const T&... values) {
        (Put(out, values), ...);
    }
};

}  // namespace detail

template <typename T>
void Put(std::string& out, const T& value) {
    if constexpr (detail::HasFields<T>::value) {
        detail::FieldWriter writer{out};
        Fields<T>::Visit(writer, value);
    } else if constexpr (detail::IsPair<T>::value) {
        Put(out, value.first);
        Put(out, value.second);
    } else if constexpr (detail::IsVector<T>::value) {
        Put(out, static_cast<uint64_t>(value.size()));
        if constexpr (detail::kPlain<typename T::value_type>) {
            out.append(reinterpret_cast<const char*>(value.data()),
                       value.size() * sizeof(typename T::value_type));
        } else {
            for (const auto& element : value) Put(out, element);
        }
    } else if constexpr (detail::IsFixedEigen<T>::value) {
        for (Eigen::Index i = 0; i < value.size(); ++i) Put(out, value.coeff(i));
    } else {
        static_assert(std::is_trivially_copyable_v<T>, "plain values, or name the Fields");
        out.append(reinterpret_cast<const char*>(&value), sizeof(T));
    }
}

/// @brief Put of a vector (its length, then its elements).
template <typename T>
void PutVector(std::string& out, const std::vector<T>& values) {
    Put(out, values);
}

/// @brief Bytes of another encoding, with their length.
inline void PutBytes(std::string& out, const std::string& bytes) {
    Put(out, static_cast<uint64_t>(bytes.size()));
    out += bytes;
}

/// @brief Reads what Put and PutBytes wrote, in the same order.
class ByteReader {
public:
    /// @param what names the answer in errors ("walls: a rank's answer is cut short").
    ByteReader(const std::string& bytes, std::string what)
        : bytes_(bytes), what_(std::move(what)) {}
    template <typename T>
    T Get() {
        T value{};
        Read(value);
        return value;
    }
    template <typename T>
    std::vector<T> GetVector() {
        return Get<std::vector<T>>();
    }
    std::string GetBytes() {
        const auto n = Get<uint64_t>();
        if (n > bytes_.size() - at_) Fail();
        std::string bytes = bytes_.substr(at_, n);
        at_ += n;
        return bytes;
    }
    [[nodiscard]] std::string Rest() const { return bytes_.substr(at_); }

    /// @brief Reads each of `values` in turn (what Fields<T>::Visit calls when reading).
    template <typename... T>
    void operator()(T&... values) {
        (Read(values), ...);
    }

private:
    template <typename T>
    void Read(T& value) {
        if constexpr (detail::HasFields<T>::value) {
            Fields<T>::Visit(*this, value);
        } else if constexpr (detail::IsPair<T>::value) {
            Read(value.first);
            Read(value.second);
        } else if constexpr (detail::IsVector<T>::value) {
            using Element = typename T::value_type;
            const auto n = Get<uint64_t>();
            // A cut answer fails before it allocates: a plain element takes its size, any
            // other at least a byte.
            const size_t least = detail::kPlain<Element> ? std::max<size_t>(1, sizeof(Element)) : 1;
            if (n > (bytes_.size() - at_) / least) Fail();
            value.clear();
            value.resize(n);  // every element is read next
            if constexpr (detail::kPlain<Element>) {
                Take(value.data(), value.size() * sizeof(Element));
            } else {
                for (Element& element : value) Read(element);
            }
        } else if constexpr (detail::IsFixedEigen<T>::value) {
            for (Eigen::Index i = 0; i < value.size(); ++i) Read(value.coeffRef(i));
        } else {
            static_assert(std::is_trivially_copyable_v<T>, "plain values, or name the Fields");
            Take(&value, sizeof(T));
        }
    }
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
