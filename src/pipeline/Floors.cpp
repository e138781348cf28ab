#include "strata/pipeline/Floors.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "strata/core/Error.hpp"
#include "strata/registration/MapRegion.hpp"

namespace strata::pipeline {

std::vector<FloorRecord> ReadFloors(const store::MapStore& map) {
    std::vector<FloorRecord> floors;
    for (const store::ProductRow& row : map.ProductRows("floors")) {
        const nlohmann::json j = nlohmann::json::parse(row.json, nullptr, false);
        FloorRecord f;
        try {
            f.index = j.at("floor").get<int>();
            f.session = j.at("session").get<int64_t>();
            f.z_m = j.at("z_m").get<double>();
            const std::vector<double> T = j.at("T_map_floor").get<std::vector<double>>();
            if (T.size() != 16) throw std::out_of_range("T_map_floor needs 16 numbers");
            for (int i = 0; i < 16; ++i) f.T_map_floor(i / 4, i % 4) = T[static_cast<size_t>(i)];
        } catch (const std::exception& e) {
            throw FormatError(map.dir().string() + ": floor row " + std::to_string(row.id) +
                              " is damaged (" + e.what() + ")");
        }
        floors.push_back(f);
    }
    std::sort(floors.begin(), floors.end(),
              [](const FloorRecord& a, const FloorRecord& b) { return a.index < b.index; });
    return floors;
}

int64_t WriteFloors(store::MapStore& map, const std::vector<FloorRecord>& floors) {
    store::ProductCommit product;
    product.kind = "floors";
    for (const FloorRecord& f : floors) {
        std::vector<double> T;
        for (int i = 0; i < 16; ++i) T.push_back(f.T_map_floor(i / 4, i % 4));
        product.rows.push_back(nlohmann::json{
            {"floor", f.index},
            {"session", f.session},
            {"z_m", f.z_m},
            {"T_map_floor", T}}.dump());
    }
    return map.CommitProduct(product);
}

std::vector<Eigen::Vector3d> FloorPoints(const store::MapStore& map,
                                         const store::Snapshot& snapshot,
                                         const FloorRecord& floor) {
    std::vector<Eigen::Vector3d> points = registration::SessionPoints(map, snapshot, floor.session);
    const Eigen::Isometry3d T(floor.T_map_floor);
    for (Eigen::Vector3d& p : points) p = T * p;
    return points;
}

}  // namespace strata::pipeline
