#pragma once
// Shared by the end-to-end tests of the `strata` program: running it, a synthetic KITTI sequence,
// scratch directories and a byte-level view of a map's tile files.

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "TempPath.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PoseFiles.hpp"

namespace strata::tools::test {

namespace fs = std::filesystem;

struct Result {
    int code = -1;    // exit code; -1 when the program did not exit by itself
    int signal = 0;   // the signal that ended it (a crash), else 0
    std::string out;  // stdout and stderr together
};

/// Runs `strata ARGS` through the shell (which execs it, so the status is the program's own) and
/// waits for it. Nothing here signals the program: death by a signal is a crash and fails the
/// calling test whatever it expected of the exit code.
inline Result Strata(const std::string& args) {
    const std::string cmd = "exec " + std::string(STRATA_BINARY) + " " + args + " 2>&1";
    Result r;
    FILE* pipe = ::popen(cmd.c_str(), "r");
    std::array<char, 4096> buf;
    while (pipe && std::fgets(buf.data(), buf.size(), pipe)) r.out += buf.data();
    const int status = pipe ? ::pclose(pipe) : -1;
    if (status != -1 && WIFEXITED(status)) r.code = WEXITSTATUS(status);
    if (status != -1 && WIFSIGNALED(status)) r.signal = WTERMSIG(status);
    if (r.signal != 0) {
        ADD_FAILURE() << "strata " << args << " died by signal " << r.signal << ":\n" << r.out;
    }
    return r;
}

/// The exit codes of tools/strata/Main.cpp, one per kind of strata::Error (README, "Exit codes").
enum ExitCode : int { kFailed = 1, kUsage = 2, kLocked = 3, kRefused = 4, kNotFound = 5,
                      kBadFormat = 6 };

/// A normal exit with exactly `code` whose output contains `message`: a crash, another code or a
/// silent failure is not accepted. Use as EXPECT_TRUE(FailedWith(r, kNotFound, "no map")).
inline ::testing::AssertionResult FailedWith(const Result& r, int code, const std::string& message) {
    if (r.signal != 0) {
        return ::testing::AssertionFailure() << "died by signal " << r.signal << ":\n" << r.out;
    }
    if (r.code != code) {
        return ::testing::AssertionFailure() << "exit code " << r.code << ", expected " << code
                                             << ":\n" << r.out;
    }
    if (r.out.find(message) == std::string::npos) {
        return ::testing::AssertionFailure() << "output does not name \"" << message << "\":\n"
                                             << r.out;
    }
    return ::testing::AssertionSuccess();
}

/// A `strata` process started with Spawn.
struct Child {
    pid_t pid = -1;
    std::chrono::steady_clock::time_point start;
};

/// How a Child ended.
struct Outcome {
    bool killed = false;  // by our SIGKILL
    int code = -1;        // exit code when it exited by itself
    double seconds = 0.0;
};

/// Starts `strata ARGS...` with fork + execv (so the caller has the pid to signal), its stdout and
/// stderr going to `log`. `file_size_limit` > 0 caps every file the process writes
/// (RLIMIT_FSIZE, with SIGXFSZ ignored so a write fails with EFBIG, as on a full disk).
inline Child Spawn(const std::vector<std::string>& args, const fs::path& log,
                   rlim_t file_size_limit = 0) {
    // Everything the child needs is prepared here: between fork and execv only async-signal-safe
    // calls are allowed (the test process runs TBB threads).
    std::vector<std::string> words{STRATA_BINARY};
    words.insert(words.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return {};
    Child child;
    child.start = std::chrono::steady_clock::now();
    child.pid = ::fork();
    if (child.pid == 0) {
        ::dup2(fd, STDOUT_FILENO);
        ::dup2(fd, STDERR_FILENO);
        if (file_size_limit > 0) {
            const rlimit limit{file_size_limit, file_size_limit};
            ::setrlimit(RLIMIT_FSIZE, &limit);
            ::signal(SIGXFSZ, SIG_IGN);
        }
        ::execv(argv[0], argv.data());
        ::_exit(127);
    }
    ::close(fd);
    return child;
}

/// Waits for `child` until `deadline` (polling), then SIGKILLs it if it is still running.
inline Outcome KillAt(const Child& child, std::chrono::steady_clock::time_point deadline) {
    constexpr auto kPoll = std::chrono::milliseconds(1);
    Outcome out;
    if (child.pid <= 0) return out;  // fork failed: there is nothing to wait for
    int status = 0;
    pid_t done = 0;
    while ((done = ::waitpid(child.pid, &status, WNOHANG)) == 0 &&
           std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(kPoll);
    }
    if (done == 0) {
        ::kill(child.pid, SIGKILL);
        done = ::waitpid(child.pid, &status, 0);
    }
    out.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - child.start).count();
    if (done != child.pid) return out;
    out.killed = WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL;
    out.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return out;
}

/// Waits for `child` to exit by itself.
inline Outcome Wait(const Child& child) {
    return KillAt(child, std::chrono::steady_clock::time_point::max());
}

/// The whole of a small text file.
inline std::string ReadText(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

/// Every tile file of a map with its bytes: equal before and after means the map is untouched.
/// The catalog is left out (SQLite may checkpoint it on any open); compare its view instead.
inline std::map<std::string, std::string> MapFiles(const fs::path& map) {
    std::map<std::string, std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(map)) {
        if (!e.is_regular_file() || e.path().filename() == "writer.lock") continue;
        if (e.path().filename().string().rfind("catalog.sqlite", 0) == 0) continue;
        std::ifstream in(e.path(), std::ios::binary);
        std::ostringstream bytes;
        bytes << in.rdbuf();
        files[fs::relative(e.path(), map).string()] = bytes.str();
    }
    return files;
}

/// What MakeSequence writes. The defaults are a 6 x 5 x 3 m room seen from three poses.
struct SequenceSpec {
    int scans = 3;
    int points_per_scan = 4000;
    Eigen::Vector3d room_half_m = Eigen::Vector3d(3.0, 2.5, 1.5);
    double step_m = 0.5;  // the sensor moves this far along x per scan
    unsigned seed = 5;
};

/// A KITTI sequence (velodyne/*.bin and poses.txt) of a box room centred on each sensor pose:
/// good enough for a test, and deterministic for a given spec.
inline fs::path MakeSequence(const fs::path& dir, const SequenceSpec& spec = {}) {
    fs::remove_all(dir);
    fs::create_directories(dir / "velodyne");
    std::mt19937 rng(spec.seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Eigen::Isometry3d> poses;
    for (int k = 0; k < spec.scans; ++k) {
        Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
        T.translation() = Eigen::Vector3d(spec.step_m * k + 0.13, 0.07, 0.03);
        poses.push_back(T);
        std::vector<Eigen::Vector3d> points;
        for (int i = 0; i < spec.points_per_scan; ++i) {
            // z, y, x, one draw each: argument order is unspecified (gcc right to left, clang
            // left to right) and the scan must not depend on the compiler; gcc's order is kept.
            Eigen::Vector3d d;
            d.z() = u(rng);
            d.y() = u(rng);
            d.x() = u(rng);
            const double t = (spec.room_half_m.array() / d.array().abs()).minCoeff();
            points.push_back(d * t);
        }
        char name[32];
        std::snprintf(name, sizeof(name), "%06d.bin", k);
        strata::io::WriteKittiBin(dir / "velodyne" / name, points);
    }
    strata::io::WriteKittiPoses(dir / "poses.txt", poses);
    return dir;
}

/// A scratch path unique to this process, removed first and at exit: "strata_cli_NAME_PID".
inline fs::path Temp(const std::string& name) {
    return strata::test::TempPath("cli_" + name);
}

}  // namespace strata::tools::test
