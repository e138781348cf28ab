#include "strata/io/AtomicFile.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

#include "strata/core/Error.hpp"

namespace strata::io {
namespace {

namespace fs = std::filesystem;

// Unique per process and call, so concurrent exports to one directory never share a temporary.
fs::path TemporarySibling(const fs::path& path) {
    static std::atomic<unsigned> counter{0};
    fs::path tmp = path;
    tmp.replace_filename("." + path.filename().string() + ".tmp-" + std::to_string(::getpid()) +
                         "-" + std::to_string(counter++));
    return tmp;
}

// Flushes the file's data to the device, so the rename never publishes an empty file after a crash.
bool SyncFile(const fs::path& file) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return false;
    const bool ok = ::fsync(fd) == 0;
    return ::close(fd) == 0 && ok;
}

[[noreturn]] void Fail(const fs::path& path, const fs::path& tmp, const std::string& why) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw IoError("cannot write '" + path.string() + "': " + why);
}

}  // namespace

void WriteFileAtomically(const fs::path& path, const std::function<void(std::ostream&)>& write) {
    if (path.empty() || !path.has_filename()) {
        throw InvalidArgumentError("output path '" + path.string() + "' does not name a file");
    }
    const fs::path tmp = TemporarySibling(path);
    std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
    if (!os.is_open()) {
        const std::string reason = std::strerror(errno);
        Fail(path, tmp, "cannot create '" + tmp.string() + "' (" + reason + ")");
    }
    // The stream state is the only reliable sign of a full disk: check it after the writes, the
    // flush and the close. A file stream keeps no error code, so the cause is errno as the
    // failing write(2) left it, read before any other call can change it.
    int write_errno = 0;
    try {
        errno = 0;
        write(os);
        if (!os) write_errno = errno;
    } catch (const std::exception& e) {
        os.close();
        Fail(path, tmp, e.what());
    }
    if (os) {
        errno = 0;
        os.flush();
        if (!os) write_errno = errno;
    }
    const bool written = os.good();
    errno = 0;
    os.close();
    if (written && os.fail()) write_errno = errno;
    if (!written || os.fail()) {
        Fail(path, tmp,
             std::string("write error (") +
                 (write_errno ? std::strerror(write_errno) : "disk full or I/O error") + ")");
    }
    if (!SyncFile(tmp)) Fail(path, tmp, std::string("fsync failed (") + std::strerror(errno) + ")");
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec)
        Fail(path, tmp, "cannot rename '" + tmp.string() + "' into place (" + ec.message() + ")");
}

}  // namespace strata::io
