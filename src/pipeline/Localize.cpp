#include "strata/pipeline/Localize.hpp"

#include <algorithm>
#include <functional>

#include "strata/core/Error.hpp"
#include "strata/pipeline/Floors.hpp"
#include "strata/pipeline/ScanSource.hpp"

namespace strata::pipeline {

namespace {

namespace reg = registration;

// The storey's slice of the stacked map (every storey moved into the map frame, then cut) as a
// surface, then the scan `read` gives registered to it.
Localization Run(const store::MapStore& map, const LocalizeOptions& options,
                 const std::function<const std::vector<Eigen::Vector3d>&()>& read) {
    options.Validate();
    const std::vector<FloorRecord> floors = ReadFloors(map);
    const auto it = std::find_if(floors.begin(), floors.end(),
                                 [&](const FloorRecord& f) { return f.index == options.floor; });
    if (it == floors.end()) {
        throw InvalidArgumentError("--floor " + std::to_string(options.floor) + ": " +
                                   map.dir().string() + " has " + std::to_string(floors.size()) +
                                   " floors recorded (strata stack records them)");
    }
    const store::Snapshot snapshot = map.Latest();
    std::vector<Eigen::Vector3d> slice;
    const Eigen::AlignedBox3d box = options.slice.Box(it->z_m);
    for (const FloorRecord& f : floors) {
        for (const Eigen::Vector3d& p : FloorPoints(map, snapshot, f)) {
            if (box.contains(p)) slice.push_back(p);
        }
    }
    reg::RegistrationConfig config = options.align.config;
    config.min_source_range_m = options.align.min_range_m;
    config.max_source_range_m = options.align.max_range_m;
    const reg::Surface surface = reg::Surface::FromPoints(slice, config.surface);
    if (surface.empty()) {
        throw RefusedError("floor " + std::to_string(options.floor) +
                           " has no surface in its slice");
    }
    const std::vector<Eigen::Vector3d>& points = read();
    Localization l;
    l.floor = options.floor;
    l.z_m = it->z_m;
    l.alignment.result = reg::RegisterPoints(
        surface, points, options.guess.value_or(Eigen::Isometry3d(it->T_map_floor)), config);
    l.alignment.map_points = slice.size();
    l.alignment.total_ms = l.alignment.result.time_ms;
    return l;
}

}  // namespace

void LocalizeOptions::Validate() const {
    slice.Validate();
    if (guess && !guess->matrix().allFinite()) {
        throw InvalidArgumentError("the guess must be finite");
    }
}

AlignOptions LocalizeOptions::DefaultAlign() {
    AlignOptions align;
    align.min_range_m = 0.5;
    align.config = reg::LocalizationRegistration();
    return align;
}

Localization Localize(const store::MapStore& map, const std::vector<Eigen::Vector3d>& points,
                      const LocalizeOptions& options) {
    return Run(map, options, [&]() -> const std::vector<Eigen::Vector3d>& { return points; });
}

Localization LocalizeFile(const store::MapStore& map, const std::filesystem::path& scan_file,
                          const LocalizeOptions& options) {
    core::Scan scan;  // read once the storey is found
    return Run(map, options, [&]() -> const std::vector<Eigen::Vector3d>& {
        scan = ReadScanFile(scan_file);
        return scan.points;
    });
}

nlohmann::json LocalizationJson(const Localization& l) {
    nlohmann::json j = AlignmentJson(l.alignment);
    j["floor"] = l.floor;
    j["z_m"] = l.z_m;
    return j;
}

}  // namespace strata::pipeline
