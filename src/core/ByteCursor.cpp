#include "strata/core/ByteCursor.hpp"

#include "strata/core/Error.hpp"

namespace strata::core {

size_t ScalarSize(ScalarType type) {
    switch (type) {
        case ScalarType::kI8:
        case ScalarType::kU8:
            return 1;
        case ScalarType::kI16:
        case ScalarType::kU16:
            return 2;
        case ScalarType::kI32:
        case ScalarType::kU32:
        case ScalarType::kF32:
            return 4;
        case ScalarType::kI64:
        case ScalarType::kU64:
        case ScalarType::kF64:
            return 8;
    }
    return 0;
}

double LoadAsDouble(const uint8_t* p, ScalarType type, bool big_endian) {
    switch (type) {
        case ScalarType::kI8:
            return LoadScalar<int8_t>(p, big_endian);
        case ScalarType::kU8:
            return LoadScalar<uint8_t>(p, big_endian);
        case ScalarType::kI16:
            return LoadScalar<int16_t>(p, big_endian);
        case ScalarType::kU16:
            return LoadScalar<uint16_t>(p, big_endian);
        case ScalarType::kI32:
            return LoadScalar<int32_t>(p, big_endian);
        case ScalarType::kU32:
            return LoadScalar<uint32_t>(p, big_endian);
        case ScalarType::kI64:
            return static_cast<double>(LoadScalar<int64_t>(p, big_endian));
        case ScalarType::kU64:
            return static_cast<double>(LoadScalar<uint64_t>(p, big_endian));
        case ScalarType::kF32:
            return LoadScalar<float>(p, big_endian);
        case ScalarType::kF64:
            return LoadScalar<double>(p, big_endian);
    }
    return 0.0;
}

void ByteCursor::Seek(size_t pos, const char* what) {
    if (pos > size_) {
        Fail(std::string(what) + " at byte " + std::to_string(pos) + " lies past the end of the " +
             std::to_string(size_) + "-byte file");
    }
    pos_ = pos;
}

void ByteCursor::Fail(const std::string& message) const {
    throw FormatError(file_ + ": " + message);
}

void ByteCursor::FailTruncated(size_t n, const char* what) const {
    Fail("truncated: " + std::string(what) + " needs " + std::to_string(n) + " bytes at byte " +
         std::to_string(pos_) + ", but only " + std::to_string(remaining()) + " remain");
}

}  // namespace strata::core
