#include "strata/pipeline/OpenOrCreate.hpp"

#include <cmath>

#include "strata/core/Error.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::pipeline {

store::StoreSettings NewMapSettings(const MapRequest& request) {
    request.rule.Validate();
    store::StoreSettings settings;
    settings.voxel_size_m = request.voxel_size_m.value_or(settings.voxel_size_m);
    settings.tile_size_m = request.tile_size_m;
    settings.integration = request.rule.ForNewMap();  // recorded: every later session fuses alike
    if (request.origin) {
        settings.origin = *request.origin;
    } else if (!request.georeference_from.empty() &&
               io::LowerExtension(request.georeference_from) == ".las") {
        settings.origin = io::ReadLasHeader(request.georeference_from).min.array().floor().matrix();
    }
    return settings;
}

OpenedMap CreateMap(const std::filesystem::path& dir, const MapRequest& request) {
    const store::StoreSettings settings = NewMapSettings(request);
    if (store::MapStore::IsMap(dir)) {
        throw InvalidArgumentError(dir.string() + " holds a map already; open it instead");
    }
    return {store::MapStore::Create(dir, settings), true, settings.integration};
}

OpenedMap OpenOrCreateMap(const std::filesystem::path& dir, const MapRequest& request) {
    request.rule.Validate();
    if (!store::MapStore::IsMap(dir)) return CreateMap(dir, request);
    OpenedMap opened{store::MapStore::Open(dir, store::MapStore::Access::kWrite), false, {}};
    opened.rule = ResolveRule(opened.map.settings(), dir.string(), request.rule);
    const double voxel = opened.map.settings().voxel_size_m;
    if (request.voxel_size_m && std::abs(voxel - *request.voxel_size_m) > 1e-12) {
        throw InvalidArgumentError(dir.string() + " has voxel size " + std::to_string(voxel) +
                                   " m; --voxel " + std::to_string(*request.voxel_size_m) +
                                   " cannot change it");
    }
    return opened;
}

}  // namespace strata::pipeline
