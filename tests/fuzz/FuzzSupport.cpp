#include "FuzzSupport.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <typeinfo>

namespace strata::fuzz {
namespace {

namespace fs = std::filesystem;

constexpr const char* kPrefix = "strata-fuzz-";

// libFuzzer ends with _Exit (time limit, crash), which skips atexit: folders of processes that
// are gone are removed by the next run instead.
void RemoveStaleScratchDirs(const fs::path& base) {
    std::error_code ec;
    for (auto it = fs::directory_iterator(base, ec); !ec && it != fs::directory_iterator();
         it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.rfind(kPrefix, 0) != 0) continue;
        const long pid = std::strtol(name.c_str() + std::strlen(kPrefix), nullptr, 10);
        if (pid <= 0 || (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH)) {
            std::error_code ignored;
            fs::remove_all(it->path(), ignored);
        }
    }
}

fs::path MakeScratchDir() {
    std::error_code ec;
    const fs::path base =
        fs::is_directory("/dev/shm", ec) ? fs::path("/dev/shm") : fs::temp_directory_path();
    RemoveStaleScratchDirs(base);
    const fs::path dir = base / (kPrefix + std::to_string(::getpid()));
    fs::remove_all(dir, ec);
    fs::create_directories(dir);
    return dir;
}

void RemoveScratchDir() {
    std::error_code ec;
    fs::remove_all(ScratchDir(), ec);
}

}  // namespace

const fs::path& ScratchDir() {
    static const fs::path dir = [] {
        fs::path made = MakeScratchDir();
        std::atexit(RemoveScratchDir);
        return made;
    }();
    return dir;
}

void WriteBytes(const fs::path& path, const char* data, size_t size) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(data, static_cast<std::streamsize>(size));
    out.close();
    if (!out) throw std::logic_error("fuzz harness: cannot write " + path.string());
}

fs::path WriteInput(const uint8_t* data, size_t size, const std::string& name) {
    const fs::path path = ScratchDir() / name;
    WriteBytes(path, reinterpret_cast<const char*>(data), size);
    return path;
}

void Expect(bool ok, const char* what) {
    if (ok) return;
    std::fprintf(stderr, "strata fuzz: contract broken: %s\n", what);
    std::abort();
}

void RejectUnexpected(const std::exception& e) {
    const char* strict = std::getenv("STRATA_FUZZ_STRICT_KINDS");
    const bool legacy =
        typeid(e) == typeid(std::runtime_error) || typeid(e) == typeid(std::invalid_argument);
    if (legacy && (strict == nullptr || std::strcmp(strict, "1") != 0)) return;
    std::fprintf(stderr, "strata fuzz: %s thrown, not a strata::Error kind: %s\n", typeid(e).name(),
                 e.what());
    std::abort();
}

void ExpectValidScan(const core::Scan& scan, bool finite_points) {
    try {
        scan.Validate();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "strata fuzz: %s\n", e.what());
        Expect(false, "a reader returned an inconsistent scan");
    }
    if (!finite_points) return;
    for (const Eigen::Vector3d& p : scan.points) Expect(p.allFinite(), "a non-finite point");
}

}  // namespace strata::fuzz
