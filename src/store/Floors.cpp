// Floors of a building map (strata stack): which session is which storey, its frame and height.
// Kept as `floor.<index>` rows of the settings table, so no schema change is needed; readers of
// older strata ignore them.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "Catalog.hpp"
#include "MapStoreImpl.hpp"

namespace strata::store {

namespace {

constexpr const char* kFloorKeyPrefix = "floor.";

std::string FloorValue(const FloorRecord& f) {
    std::ostringstream os;
    os.precision(17);
    os << f.session << " " << f.z_m;
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) os << " " << f.T_map_floor(r, c);
    }
    return os.str();
}

}  // namespace

void MapStore::RecordFloor(const FloorRecord& floor) {
    impl_->RequireWriter("recording a floor");
    if (floor.index < 0) throw std::invalid_argument("floor index must be >= 0");
    if (!floor.T_map_floor.allFinite() || !std::isfinite(floor.z_m)) {
        throw std::invalid_argument("floor " + std::to_string(floor.index) +
                                    ": transform and height must be finite");
    }
    const detail::Database& db = *impl_->db;
    detail::Transaction tx(db, detail::Transaction::Kind::kWrite);
    detail::Statement q(db, "INSERT OR REPLACE INTO settings(key, value) VALUES (?, ?)");
    q.Bind(1, kFloorKeyPrefix + std::to_string(floor.index)).Bind(2, FloorValue(floor)).Run();
    tx.Commit();
}

std::vector<FloorRecord> MapStore::Floors() const {
    const detail::Database& db = *impl_->db;
    detail::Statement q(db, "SELECT key, value FROM settings WHERE key LIKE 'floor.%'");
    std::vector<FloorRecord> out;
    while (q.Step()) {
        FloorRecord f;
        std::istringstream key(q.Text(0).substr(6)), value(q.Text(1));
        key >> f.index;
        value >> f.session >> f.z_m;
        for (int i = 0; i < 16; ++i) value >> f.T_map_floor(i / 4, i % 4);
        if (!key || !value) {
            throw std::runtime_error(db.file().string() + ": setting '" + q.Text(0) +
                                     "' is not a floor record");
        }
        out.push_back(f);
    }
    std::sort(out.begin(), out.end(),
              [](const FloorRecord& a, const FloorRecord& b) { return a.index < b.index; });
    return out;
}

}  // namespace strata::store
