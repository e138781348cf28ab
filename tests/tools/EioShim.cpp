// LD_PRELOAD shim for the fault tests: chosen calls fail on files whose path contains
// $STRATA_EIO_ON, the way a failing or full disk makes them fail.
//   STRATA_EIO_CALLS  sync (default): fsync and fdatasync, a write-back error reported at flush;
//                     write: write, writev, pwrite and pwrite64, an error on the write itself
//   STRATA_EIO_ERRNO  EIO (default) or ENOSPC
#include <dlfcn.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace {

bool Env(const char* name, const char* value) {
    const char* env = std::getenv(name);
    return env && std::strcmp(env, value) == 0;
}

// Whether a call of this kind ("sync" or "write") on fd is to fail; sets errno if so.
bool Fails(int fd, const char* kind) {
    const char* needle = std::getenv("STRATA_EIO_ON");
    if (!needle || !*needle) return false;
    const char* calls = std::getenv("STRATA_EIO_CALLS");
    if (!(calls && *calls ? std::strcmp(calls, kind) == 0 : std::strcmp(kind, "sync") == 0)) {
        return false;
    }
    char link[64];
    char path[4096];
    std::snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
    const ssize_t n = readlink(link, path, sizeof path - 1);
    if (n < 0) return false;
    path[n] = '\0';
    if (std::strstr(path, needle) == nullptr) return false;
    errno = Env("STRATA_EIO_ERRNO", "ENOSPC") ? ENOSPC : EIO;
    return true;
}

// The next definition of `name` after this library's (libc's, or a sanitizer's interceptor).
template <typename Fn>
Fn Real(const char* name) {
    return reinterpret_cast<Fn>(dlsym(RTLD_NEXT, name));
}

using SyncFn = int (*)(int);
using WriteFn = ssize_t (*)(int, const void*, size_t);
using WritevFn = ssize_t (*)(int, const iovec*, int);
using PwriteFn = ssize_t (*)(int, const void*, size_t, off_t);
using Pwrite64Fn = ssize_t (*)(int, const void*, size_t, off64_t);

}  // namespace

extern "C" int fsync(int fd) {
    if (Fails(fd, "sync")) return -1;
    static const auto real = Real<SyncFn>("fsync");
    return real(fd);
}

extern "C" int fdatasync(int fd) {
    if (Fails(fd, "sync")) return -1;
    static const auto real = Real<SyncFn>("fdatasync");
    return real(fd);
}

extern "C" ssize_t write(int fd, const void* buf, size_t count) {
    if (Fails(fd, "write")) return -1;
    static const auto real = Real<WriteFn>("write");
    return real(fd, buf, count);
}

extern "C" ssize_t writev(int fd, const iovec* iov, int iovcnt) {
    if (Fails(fd, "write")) return -1;
    static const auto real = Real<WritevFn>("writev");
    return real(fd, iov, iovcnt);
}

extern "C" ssize_t pwrite(int fd, const void* buf, size_t count, off_t offset) {
    if (Fails(fd, "write")) return -1;
    static const auto real = Real<PwriteFn>("pwrite");
    return real(fd, buf, count, offset);
}

extern "C" ssize_t pwrite64(int fd, const void* buf, size_t count, off64_t offset) {
    if (Fails(fd, "write")) return -1;
    static const auto real = Real<Pwrite64Fn>("pwrite64");
    return real(fd, buf, count, offset);
}
