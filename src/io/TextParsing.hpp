#pragma once

// Private to io: line and number parsing shared by the text, PCD/PLY header and pose readers.
// Numbers are parsed with std::from_chars, so the result never depends on the C locale.

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace strata::io::detail {

/// @brief Throws NotFoundError when `path` does not exist, InvalidArgumentError when it is a
/// directory; returns otherwise (the file may still be unreadable).
void RequireFile(const std::filesystem::path& path);

/// @brief Throws the error for a file that exists but would not open for reading: IoError with
/// the system's reason (no permission, ...), or what RequireFile throws.
[[noreturn]] void FailOpen(const std::filesystem::path& path);

/// @brief Reads a whole text file; throws NotFoundError, InvalidArgumentError or IoError naming
/// it (see RequireFile, FailOpen).
[[nodiscard]] std::string ReadTextFile(const std::filesystem::path& path);

/// @brief Throws FormatError "<file>: header line <line>: <message>" (PCD and PLY headers).
[[noreturn]] void FailHeader(const std::string& file, size_t line, const std::string& message);

/// @brief Parses the whole token as a double ("1.5", "-2e3", "+4", "nan"); false otherwise.
[[nodiscard]] bool ParseDouble(std::string_view token, double& value);

/// @brief Parses the whole token as an unsigned integer that fits in uint64_t.
[[nodiscard]] bool ParseUint(std::string_view token, unsigned long long& value);

/// @brief Drops everything from the first `#`.
[[nodiscard]] std::string_view StripComment(std::string_view line);

/// @brief Splits on spaces, tabs, carriage returns and commas; empty fields are skipped.
void SplitFields(std::string_view line, std::vector<std::string_view>& fields);

/// @brief Iterates the lines of a text buffer (LF or CRLF), counting them from 1.
class LineReader {
public:
    explicit LineReader(std::string_view text) : text_(text) {}

    /// @brief Sets `line` to the next line without its terminator; false at the end.
    bool Next(std::string_view& line) {
        if (pos_ >= text_.size()) return false;
        const size_t end = text_.find('\n', pos_);
        const size_t stop = end == std::string_view::npos ? text_.size() : end;
        line = text_.substr(pos_, stop - pos_);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        pos_ = stop == text_.size() ? stop : stop + 1;
        ++line_number_;
        return true;
    }
    [[nodiscard]] size_t line_number() const { return line_number_; }
    /// @brief Byte offset just past the last line returned.
    [[nodiscard]] size_t position() const { return pos_; }

private:
    std::string_view text_;
    size_t pos_ = 0;
    size_t line_number_ = 0;
};

}  // namespace strata::io::detail
