#include "TextParsing.hpp"

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>

#include "strata/core/Error.hpp"

namespace strata::io::detail {

void FailHeader(const std::string& file, size_t line, const std::string& message) {
    throw FormatError(file + ": header line " + std::to_string(line) + ": " + message);
}

void RequireFile(const std::filesystem::path& path) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (status.type() == std::filesystem::file_type::not_found) {
        throw NotFoundError(path.string() + ": no such file");
    }
    if (status.type() == std::filesystem::file_type::directory) {
        throw InvalidArgumentError(path.string() + ": is a directory, expected a file");
    }
}

void FailOpen(const std::filesystem::path& path) {
    const int error = errno;  // before anything else can overwrite it
    RequireFile(path);
    throw IoError(path.string() + ": cannot open file for reading" +
                  (error != 0 ? std::string(": ") + std::strerror(error) : std::string()));
}

std::string ReadTextFile(const std::filesystem::path& path) {
    RequireFile(path);
    errno = 0;
    std::ifstream in(path, std::ios::binary);
    if (!in) FailOpen(path);
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) throw IoError(path.string() + ": read error");
    return buffer.str();
}

bool ParseDouble(std::string_view token, double& value) {
    // from_chars rejects a leading '+', which some writers emit.
    if (token.size() > 1 && token.front() == '+') token.remove_prefix(1);
    if (token.empty()) return false;
    const char* end = token.data() + token.size();
    const auto result = std::from_chars(token.data(), end, value);
    return result.ec == std::errc() && result.ptr == end;
}

bool ParseUint(std::string_view token, unsigned long long& value) {
    if (token.empty()) return false;
    const char* end = token.data() + token.size();
    const auto result = std::from_chars(token.data(), end, value);
    return result.ec == std::errc() && result.ptr == end;
}

std::string_view StripComment(std::string_view line) {
    const size_t hash = line.find('#');
    return hash == std::string_view::npos ? line : line.substr(0, hash);
}

void SplitFields(std::string_view line, std::vector<std::string_view>& fields) {
    fields.clear();
    constexpr std::string_view kSeparators = " \t\r,";
    size_t pos = line.find_first_not_of(kSeparators);
    while (pos != std::string_view::npos) {
        const size_t end = line.find_first_of(kSeparators, pos);
        const size_t stop = end == std::string_view::npos ? line.size() : end;
        fields.push_back(line.substr(pos, stop - pos));
        pos = stop == line.size() ? std::string_view::npos
                                  : line.find_first_not_of(kSeparators, stop);
    }
}

}  // namespace strata::io::detail
