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

void RequireNewest(const store::MapStore& map, int64_t commit, const std::string& what) {
    if (!map.writable()) {
        throw InvalidArgumentError(map.dir().string() + " is open read-only: storing " + what +
                                   " needs the map open for writing");
    }
    const int64_t newest = map.Latest().commit;
    if (commit != newest) {
        throw InvalidArgumentError("the " + what + " are of commit " + std::to_string(commit) +
                                   ", not of the newest map (commit " + std::to_string(newest) +
                                   "): only the newest map's " + what + " are stored");
    }
}

}  // namespace strata::pipeline
