#pragma once
// Shared by the end-to-end tests of the `strata` program: running it, a synthetic KITTI sequence,
// scratch directories and a byte-level view of a map's tile files.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

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

#include "SyntheticRoom.hpp"
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
/// Runs `command` through the shell, its stdout and stderr together, and waits for it.
inline Result Shell(const std::string& command) {
    const std::string cmd = command + " 2>&1";
    Result r;
    FILE* pipe = ::popen(cmd.c_str(), "r");
    std::array<char, 4096> buf;
    while (pipe && std::fgets(buf.data(), buf.size(), pipe)) r.out += buf.data();
    const int status = pipe ? ::pclose(pipe) : -1;
    if (status != -1 && WIFEXITED(status)) r.code = WEXITSTATUS(status);
    if (status != -1 && WIFSIGNALED(status)) r.signal = WTERMSIG(status);
    return r;
}

inline Result Strata(const std::string& args) {
    Result r = Shell("exec " + std::string(STRATA_BINARY) + " " + args);
    if (r.signal != 0) {
        ADD_FAILURE() << "strata " << args << " died by signal " << r.signal << ":\n" << r.out;
    }
    return r;
}

/// The exit codes of tools/strata/Main.cpp, one per kind of strata::Error (README, "Exit codes").
enum ExitCode : int {
    kFailed = 1,
    kUsage = 2,
    kLocked = 3,
    kRefused = 4,
    kNotFound = 5,
    kBadFormat = 6
};

/// A normal exit with exactly `code` whose output contains `message`: a crash, another code or a
/// silent failure is not accepted. Use as EXPECT_TRUE(FailedWith(r, kNotFound, "no map")).
inline ::testing::AssertionResult FailedWith(const Result& r, int code,
                                             const std::string& message) {
    if (r.signal != 0) {
        return ::testing::AssertionFailure() << "died by signal " << r.signal << ":\n" << r.out;
    }
    if (r.code != code) {
        return ::testing::AssertionFailure()
               << "exit code " << r.code << ", expected " << code << ":\n"
               << r.out;
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

// Scans of a box room and the tile-file view of a map (tests/support/SyntheticRoom.hpp).
using strata::test::MakeSequence;
using strata::test::MapFiles;
using strata::test::SequenceSpec;

/// A scratch path unique to this process, removed first and at exit: "strata_cli_NAME_PID".
inline fs::path Temp(const std::string& name) { return strata::test::TempPath("cli_" + name); }

}  // namespace strata::tools::test
