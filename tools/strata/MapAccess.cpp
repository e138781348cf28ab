#include "MapAccess.hpp"

#include <cstdlib>

#include "strata/io/AtomicFile.hpp"
#include "strata/io/VdbExport.hpp"

namespace strata::tools {

namespace fs = std::filesystem;

fs::path FindDataDir() {
    if (const char* env = std::getenv("STRATA_DATA_DIR"); env && *env) return env;
    for (const fs::path& candidate : {fs::path("../shared/data"), fs::path("shared/data")}) {
        if (fs::is_directory(candidate)) return fs::weakly_canonical(candidate);
    }
    return {};
}

void WriteTextFile(const std::string& path, const std::string& text) {
    io::WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

void WriteGridsFile(const openvdb::GridPtrVec& grids, const std::string& path) {
    io::WriteGrids(openvdb::GridCPtrVec(grids.begin(), grids.end()), {}, path);
}

}  // namespace strata::tools
