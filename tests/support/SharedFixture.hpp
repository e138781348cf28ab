#pragma once

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>

#include "TempPath.hpp"

namespace strata::test {

/// @brief A fixture folder made once for all the test processes of one suite run, where CTest
/// would otherwise make it again in every process that wants it (one process per test): the
/// suite's commands (tools/test.sh, tools/sanitize.sh) export STRATA_TEST_FIXTURES, a folder of
/// their own that they remove when the run ends. The first process to want `name` makes it there
/// with `make(folder)` while the others wait on a lock, then all read it. Without the variable
/// (a test program run by hand) `make` fills a scratch path of this process (TempPath), as
/// before. Its users must only read the folder, and `name` must say everything `make` depends
/// on. A process killed while making it leaves no mark of completion: the next one starts over.
inline std::filesystem::path SharedFixture(
    const std::string& name, const std::function<void(const std::filesystem::path&)>& make) {
    namespace fs = std::filesystem;
    const char* root = std::getenv("STRATA_TEST_FIXTURES");
    if (root == nullptr || *root == '\0') {
        const fs::path dir = TempPath(name);
        make(dir);
        return dir;
    }
    const fs::path dir = fs::path(root) / name;
    const std::string lock = dir.string() + ".lock", done = dir.string() + ".done";
    const int fd = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) throw std::runtime_error(lock + ": " + std::strerror(errno));
    struct Unlock {
        int fd;
        ~Unlock() { ::close(fd); }  // closing releases the lock
    } unlock{fd};
    while (::flock(fd, LOCK_EX) != 0) {
        if (errno != EINTR) throw std::runtime_error(lock + ": " + std::strerror(errno));
    }
    if (!fs::exists(done)) {
        fs::remove_all(dir);  // what a killed process left
        make(dir);
        std::ofstream(done) << "made by process " << ::getpid() << "\n";
    }
    return dir;
}

}  // namespace strata::test
