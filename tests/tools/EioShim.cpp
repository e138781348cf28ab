// LD_PRELOAD shim for the fault tests: fsync and fdatasync fail with EIO on files whose path
// contains $STRATA_EIO_ON (a disk reporting a write-back error, the moment real disks do).
#include <dlfcn.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace {

bool Matches(int fd) {
    const char* needle = std::getenv("STRATA_EIO_ON");
    if (!needle || !*needle) return false;
    char link[64];
    char path[4096];
    std::snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
    const ssize_t n = readlink(link, path, sizeof path - 1);
    if (n < 0) return false;
    path[n] = '\0';
    return std::strstr(path, needle) != nullptr;
}

using SyncFn = int (*)(int);

}  // namespace

extern "C" int fsync(int fd) {
    if (Matches(fd)) {
        errno = EIO;
        return -1;
    }
    static const auto real = reinterpret_cast<SyncFn>(dlsym(RTLD_NEXT, "fsync"));
    return real(fd);
}

extern "C" int fdatasync(int fd) {
    if (Matches(fd)) {
        errno = EIO;
        return -1;
    }
    static const auto real = reinterpret_cast<SyncFn>(dlsym(RTLD_NEXT, "fdatasync"));
    return real(fd);
}
