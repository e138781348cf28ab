#pragma once
// Private to recordings: positioned reads of a recording file, never past its end. The bytes read
// are decoded through core::ByteCursor (strata/core/ByteCursor.hpp).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "strata/core/ByteCursor.hpp"

namespace strata::recordings::detail {

/// @brief Throws FormatError "<where>: <message>".
[[noreturn]] void Fail(const std::string& where, const std::string& message);

/// @brief "<file>: <what> at byte <offset>", how the container readers name a record in errors.
[[nodiscard]] std::string At(const std::string& file, const char* what, uint64_t offset);

/// @brief A file read at chosen offsets, never past its end.
class FileReader {
public:
    /// @throw NotFoundError, IoError naming the file.
    explicit FileReader(const std::filesystem::path& path);
    ~FileReader();
    FileReader(const FileReader&) = delete;
    FileReader& operator=(const FileReader&) = delete;

    [[nodiscard]] uint64_t size() const { return size_; }
    [[nodiscard]] const std::string& name() const { return name_; }

    /// @brief Bytes [offset, offset + n) into `out` (resized); FormatError naming `what` and the
    /// offset when they run past the end of the file (a truncated recording).
    void Read(uint64_t offset, size_t n, std::vector<uint8_t>& out, const char* what) const;

private:
    int fd_ = -1;
    uint64_t size_ = 0;
    std::string name_;
};

}  // namespace strata::recordings::detail
