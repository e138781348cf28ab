#include "MapAccess.hpp"

#include <cstdlib>
#include <stdexcept>

#include "strata/core/Error.hpp"
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

store::MapStore OpenMap(const fs::path& dir, store::MapStore::Access access) {
    if (!fs::exists(dir)) {
        throw NotFoundError(dir.string() + ": no map here (create one with `strata integrate " +
                                 dir.string() + " --kitti SEQ`)");
    }
    return store::MapStore::Open(dir, access);
}

store::Snapshot SelectSnapshot(const store::MapStore& map, const std::string& as_of) {
    return as_of.empty() ? map.Latest() : map.AsOf(map.FindSession(as_of));
}

void WriteTextFile(const std::string& path, const std::string& text) {
    io::WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

void WriteGridsFile(const openvdb::GridPtrVec& grids, const std::string& path) {
    io::WriteGrids(openvdb::GridCPtrVec(grids.begin(), grids.end()), {}, path);
}

}  // namespace strata::tools
