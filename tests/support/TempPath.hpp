#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace strata::test {

/// @brief A scratch path under the temporary directory, unique to this process: `name` "map.ply"
/// becomes "strata_map_PID.ply" (the extension stays last: some commands read it). Removed first,
/// and again when the process exits. CTest runs the tests of one program in parallel processes,
/// and two suites may run at once on one machine, so a fixed name would collide.
inline std::filesystem::path TempPath(const std::string& name) {
    namespace fs = std::filesystem;
    struct Registry {
        std::vector<fs::path> paths;
        ~Registry() {
            std::error_code ignored;
            for (const fs::path& p : paths) fs::remove_all(p, ignored);
        }
    };
    static Registry registry;
    const size_t dot = name.rfind('.');
    const std::string stem = name.substr(0, dot);
    const std::string extension = dot == std::string::npos ? "" : name.substr(dot);
    const fs::path p = fs::temp_directory_path() /
                       ("strata_" + stem + "_" + std::to_string(::getpid()) + extension);
    std::error_code ignored;
    fs::remove_all(p, ignored);
    registry.paths.push_back(p);
    return p;
}

}  // namespace strata::test
