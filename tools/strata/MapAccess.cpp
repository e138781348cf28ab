#include "MapAccess.hpp"

#include <cstdlib>
#include <ctime>
#include <stdexcept>

namespace strata::tools {

namespace fs = std::filesystem;

fs::path FindDataDir() {
    if (const char* env = std::getenv("STRATA_DATA_DIR"); env && *env) return env;
    for (const fs::path& candidate : {fs::path("../shared/data"), fs::path("shared/data")}) {
        if (fs::is_directory(candidate)) return fs::weakly_canonical(candidate);
    }
    return {};
}

io::MapDirectory OpenMap(const fs::path& dir) {
    if (!io::IsMapDirectory(dir)) {
        throw std::runtime_error(dir.string() + ": no map here (create one with `strata integrate " +
                                 dir.string() + " --kitti SEQ`)");
    }
    return io::LoadMapDirectory(dir);
}

std::string UtcNow() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char buf[32];
    std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

}  // namespace strata::tools
