#include "MapAccess.hpp"

#include <cstdlib>
#include <sstream>

#include "strata/core/Error.hpp"
#include "strata/io/AtomicFile.hpp"
#include "strata/io/VdbExport.hpp"
#include "strata/pipeline/RankedSession.hpp"

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

MapOnRanks OpenMapOnRanks(const std::string& path, const std::string& as_of, bool save,
                          const pipeline::Ranks& ranks) {
    MapOnRanks opened{pipeline::OpenOnRanks(path, ranks,
                                            [&] {
                                                return OpenMap(
                                                    path, save ? store::MapStore::Access::kWrite
                                                               : store::MapStore::Access::kRead);
                                            }),
                      std::nullopt};
    pipeline::OnEveryRank(ranks, [&] {
        if (ranks.root()) opened.snapshot = SelectSnapshot(opened.map, as_of);
    });
    return opened;
}

void RefuseWholeMapOutputs(const store::MapStore& map, const pipeline::Ranks& ranks, bool wanted,
                           const std::string& what, const std::function<bool()>& read_whole,
                           double budget_mb, const std::string& instead) {
    pipeline::OnEveryRank(ranks, [&] {
        if (!ranks.root() || !wanted) return;
        if (ranks.size() > 1) {
            throw RefusedError(map.dir().string() + ": " + what +
                               " draw the whole map, which the ranks of mpirun read only in "
                               "parts; run them in one process");
        }
        if (read_whole()) return;
        std::ostringstream mb;
        mb << budget_mb;
        throw RefusedError(map.dir().string() + ": " + what +
                           " draw the whole map, which exceeds --memory-budget " + mb.str() +
                           " MB; raise --memory-budget (0: no limit) or leave them out (" +
                           instead + " are found tile by tile)");
    });
}

}  // namespace strata::tools
