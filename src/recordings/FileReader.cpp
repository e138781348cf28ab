#include "FileReader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "strata/core/Error.hpp"

namespace strata::recordings::detail {

void Fail(const std::string& where, const std::string& message) {
    throw FormatError(where + ": " + message);
}

std::string At(const std::string& file, const char* what, uint64_t offset) {
    return file + ": " + what + " at byte " + std::to_string(offset);
}

FileReader::FileReader(const std::filesystem::path& path) : name_(path.string()) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (status.type() == std::filesystem::file_type::not_found) {
        throw NotFoundError(name_ + ": no such file");
    }
    if (status.type() == std::filesystem::file_type::directory) {
        throw InvalidArgumentError(name_ + ": is a directory, expected a recording file");
    }
    fd_ = ::open(name_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) {
        throw IoError(name_ + ": cannot open for reading: " + std::strerror(errno));
    }
    struct stat st {};
    if (::fstat(fd_, &st) != 0) {
        const int error = errno;
        ::close(fd_);
        throw IoError(name_ + ": cannot determine the file size: " + std::strerror(error));
    }
    size_ = static_cast<uint64_t>(st.st_size);
}

FileReader::~FileReader() {
    if (fd_ >= 0) ::close(fd_);
}

void FileReader::Read(uint64_t offset, size_t n, std::vector<uint8_t>& out,
                      const char* what) const {
    if (offset > size_ || n > size_ - offset) {
        Fail(name_, "truncated: " + std::string(what) + " at byte " + std::to_string(offset) +
                        " needs " + std::to_string(n) + " bytes, the file has " +
                        std::to_string(size_ - std::min(offset, size_)) + " more");
    }
    out.resize(n);
    size_t done = 0;
    while (done < n) {
        const ssize_t got =
            ::pread(fd_, out.data() + done, n - done, static_cast<off_t>(offset + done));
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) {
            throw IoError(name_ + ": read error at byte " + std::to_string(offset + done) + ": " +
                          std::strerror(errno));
        }
        if (got == 0) {
            Fail(name_, "the file ended at byte " + std::to_string(offset + done) +
                            " while reading " + what + " (was it cut while being read?)");
        }
        done += static_cast<size_t>(got);
    }
}

}  // namespace strata::recordings::detail
