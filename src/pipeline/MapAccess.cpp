#include "strata/pipeline/MapAccess.hpp"

#include "strata/core/Error.hpp"

namespace strata::pipeline {

namespace fs = std::filesystem;

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

}  // namespace strata::pipeline
