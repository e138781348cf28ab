// The viewer's only use of the map store (ViewSource.hpp): written against MapStore's format-4
// API (Latest / AsOf / ReadTile / Walls / Vehicles / ChangeSets / SessionHistory).
#include "ViewSource.hpp"

#include <algorithm>
#include <map>
#include <mutex>
#include <regex>

#include "strata/change/ChangeReport.hpp"
#include "strata/change/MapObserver.hpp"
#include "strata/core/Error.hpp"
#include "strata/store/MapStore.hpp"
#include "strata/vehicles/Vehicles.hpp"
#include "strata/walls/WallReport.hpp"

namespace strata::view {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json Vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json SessionJson(const store::SessionRecord& s, int64_t removed_by) {
    json alignment = json::array();
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) alignment.push_back(s.alignment(r, c));
    }
    return {{"id", s.id},         {"name", s.name},           {"source", s.source},
            {"sensor", s.sensor}, {"start_utc", s.start_utc}, {"end_utc", s.end_utc},
            {"scans", s.scans},   {"points", s.points},       {"alignment", alignment},
            {"notes", s.notes},   {"commit", s.commit},       {"removed_by_commit", removed_by}};
}

json WallJson(const store::WallRecord& w) {
    return {{"commit", w.commit},
            {"wall_id", w.wall_id},
            {"center", Vec(w.center)},
            {"normal", Vec(w.normal)},
            {"slant_deg", w.slant_deg},
            {"uncertainty_deg", w.uncertainty_deg},
            {"lean_azimuth_deg", w.lean_azimuth_deg},
            {"area_m2", w.area_m2},
            {"rms_m", w.rms_m},
            {"length_m", w.length_m},
            {"height_m", w.height_m},
            {"inliers", w.inliers}};
}

json VehicleJson(const store::VehicleRecord& v) {
    return {{"commit", v.commit},
            {"vehicle_id", v.vehicle_id},
            {"center", Vec(v.center)},
            {"size", Vec(v.size)},
            {"yaw_deg", v.yaw_deg},
            {"source", v.source},
            {"voxels", v.voxels},
            {"cleared_voxels", v.cleared_voxels},
            {"refilled_cells", v.refilled_cells},
            {"refused_cells", v.refused_cells}};
}

// The row of a saved change set; its counts are in the report (added_voxels, removed_voxels,
// unknown_voxels, objects).
json ChangeSetJson(const store::ChangeSetRecord& r) {
    return {
        {"id", r.id},     {"commit", r.commit}, {"created_utc", r.created_utc},
        {"from", r.from}, {"to", r.to},         {"report", json::parse(r.report, nullptr, false)}};
}

template <typename GridT>
typename GridT::ConstPtr Product(const store::Tile& tile, const char* name) {
    for (const openvdb::GridBase::Ptr& grid : tile.products) {
        if (grid->getName() == name) return openvdb::GridBase::constGrid<GridT>(grid);
    }
    return nullptr;
}

// The query a saved report records (ChangeReportJson's "query"); defaults for what is missing.
change::ChangeQuery QueryOf(const json& report) {
    change::ChangeQuery q;
    const json query = report.value("query", json::object());
    q.min_voxels = query.value("min_voxels", q.min_voxels);
    q.gap_voxels = query.value("gap_voxels", q.gap_voxels);
    q.surface_tolerance_voxels =
        query.value("surface_tolerance_voxels", q.surface_tolerance_voxels);
    q.observed_margin_voxels = query.value("observed_margin_voxels", q.observed_margin_voxels);
    q.grow_voxels = query.value("grow_voxels", q.grow_voxels);
    q.support_depth_voxels = query.value("support_depth_voxels", q.support_depth_voxels);
    if (query.contains("class")) q.class_filter = core::ClassFromName(query.at("class"));
    if (query.contains("region")) {
        std::vector<Eigen::Vector2d> v;
        for (const json& p : query.at("region")) v.emplace_back(p.at(0), p.at(1));
        // Region::Box's corners, in its order: rebuild it as a box, which clips exactly as the
        // saved query did.
        const bool box = v.size() == 4 && v[0].y() == v[1].y() && v[1].x() == v[2].x() &&
                         v[2].y() == v[3].y() && v[3].x() == v[0].x();
        q.region = box ? core::Region::Box(v[0].x(), v[0].y(), v[2].x(), v[2].y())
                       : core::Region::Polygon(v);
    }
    return q;
}

// The session `id_or_name` names (MapStore::FindSession), or NotFoundError listing the sessions.
int64_t SessionNamed(const store::MapStore& store, const std::string& id_or_name) {
    std::string known;
    for (const auto& [session, removed_by] : store.SessionHistory()) {
        if (std::to_string(session.id) == id_or_name || session.name == id_or_name) {
            return store.FindSession(id_or_name);
        }
        known += (known.empty() ? "" : ", ") + std::to_string(session.id) + " " + session.name;
    }
    throw NotFoundError(store.dir().string() + ": no session '" + id_or_name +
                        "' (sessions: " + (known.empty() ? "none" : known) + ")");
}

}  // namespace

struct ViewSource::Impl {
    explicit Impl(store::MapStore opened) : store(std::move(opened)) {}

    store::MapStore store;
    MapFacts facts;
    std::vector<store::Snapshot> pinned;  ///< parallel to snapshots
    std::vector<ViewSnapshot> snapshots;
    json sessions = json::array();
    json walls = json::array();
    json vehicles = json::array();
    json change_sets = json::array();
    std::vector<store::ChangeSetRecord> change_set_records;
    std::map<TileRef, store::TileVersion> versions;  ///< every tile file a snapshot names
    mutable std::mutex catalog;  ///< one catalog reader at a time (change queries)

    void Pin(store::Snapshot snapshot, int64_t as_of_session) {
        ViewSnapshot view{snapshot.commit, as_of_session, {}, {}};
        for (const store::TileVersion& v : snapshot.tiles) {
            const TileRef ref{v.key.x, v.key.y, v.version};
            view.tiles.push_back(ref);
            versions.emplace(ref, v);
        }
        for (const store::SessionRecord& s : snapshot.sessions) view.sessions.push_back(s.id);
        std::sort(view.sessions.begin(), view.sessions.end());
        snapshots.push_back(std::move(view));
        pinned.push_back(std::move(snapshot));
    }

    // One side of a saved change set, by the name `strata diff` gave it.
    std::optional<change::Observation> Side(const std::string& name, int64_t saved_at,
                                            change::MapObserver& observer) const {
        static const std::regex session(R"(session (\d+))"), as_of(R"(map as of session (\d+))");
        std::smatch m;
        if (std::regex_match(name, m, session)) return observer.Session(std::stoll(m[1]));
        if (std::regex_match(name, m, as_of)) return observer.Map(store.AsOf(std::stoll(m[1])));
        if (name == "map (newest)") {
            for (const store::Snapshot& s : pinned) {
                if (s.commit == saved_at) return observer.Map(s);
            }
        }
        return std::nullopt;  // scans never committed, or a commit no longer pinned
    }
};

ViewSource::ViewSource(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ViewSource::~ViewSource() = default;

std::shared_ptr<ViewSource> ViewSource::Open(const fs::path& dir, const std::string& as_of) {
    if (!store::MapStore::IsMap(dir)) {
        throw NotFoundError(dir.string() + ": no map here (create one with `strata integrate " +
                            dir.string() + " --kitti SEQ` or `strata demo`)");
    }
    auto impl = std::make_unique<Impl>(store::MapStore::Open(dir, store::MapStore::Access::kRead));
    Impl& s = *impl;
    const store::MapSettings& settings = s.store.settings();
    s.facts = {fs::absolute(dir).lexically_normal().filename().string(), settings.voxel_size_m,
               settings.tile_voxels, settings.origin, settings.format_version};
    if (s.facts.name.empty()) s.facts.name = fs::absolute(dir).parent_path().filename().string();

    const int64_t as_of_id = as_of.empty() ? 0 : SessionNamed(s.store, as_of);
    s.Pin(as_of.empty() ? s.store.Latest() : s.store.AsOf(as_of_id), as_of_id);
    const int64_t commit = s.snapshots.front().commit;
    for (const int64_t id : std::vector<int64_t>(s.snapshots.front().sessions)) {
        s.Pin(s.store.AsOf(id), id);
    }
    // Rows newer than the pinned commit belong to a state of the map this viewer does not show.
    for (const auto& [session, removed_by] : s.store.SessionHistory()) {
        if (session.commit <= commit) {
            s.sessions.push_back(SessionJson(session, removed_by > commit ? 0 : removed_by));
        }
    }
    for (const store::WallRecord& w : s.store.Walls()) {
        if (w.commit <= commit) s.walls.push_back(WallJson(w));
    }
    for (const store::VehicleRecord& v : s.store.Vehicles()) {
        if (v.commit <= commit) s.vehicles.push_back(VehicleJson(v));
    }
    for (const store::ChangeSetRecord& r : s.store.ChangeSets()) {
        if (r.commit > commit) continue;
        s.change_sets.push_back(ChangeSetJson(r));
        s.change_set_records.push_back(r);
    }
    return std::shared_ptr<ViewSource>(new ViewSource(std::move(impl)));
}

const MapFacts& ViewSource::facts() const { return impl_->facts; }
const std::vector<ViewSnapshot>& ViewSource::snapshots() const { return impl_->snapshots; }
const json& ViewSource::sessions() const { return impl_->sessions; }
const json& ViewSource::walls() const { return impl_->walls; }
const json& ViewSource::vehicles() const { return impl_->vehicles; }
const json& ViewSource::change_sets() const { return impl_->change_sets; }

TileGrids ViewSource::ReadTile(const TileRef& ref) const {
    const auto it = impl_->versions.find(ref);
    if (it == impl_->versions.end()) {
        throw NotFoundError("tile " + std::to_string(ref.x) + "_" + std::to_string(ref.y) + " v" +
                            std::to_string(ref.version) + " is in no snapshot of this view");
    }
    const store::Tile tile = impl_->store.ReadTile(it->second);
    TileGrids grids;
    grids.occupancy = tile.fused.occupancy;
    grids.label = tile.fused.label;
    grids.endpoints = tile.fused.endpoints;
    for (const store::SessionLayer& layer : tile.layers) {
        grids.sessions.emplace_back(layer.session, layer.occupied);
        grids.sessions_free.emplace_back(layer.session, layer.free);
    }
    grids.slant_deg = Product<openvdb::FloatGrid>(tile, walls::product_names::kSlantDeg);
    grids.wall_id = Product<openvdb::Int32Grid>(tile, walls::product_names::kWallId);
    grids.cleared = Product<openvdb::Int32Grid>(tile, vehicles::grid_names::kCleared);
    grids.refilled = Product<openvdb::FloatGrid>(tile, vehicles::grid_names::kRefilled);
    return grids;
}

ChangeMasks ViewSource::DiffSessions(int64_t a, int64_t b) const {
    const std::vector<int64_t>& alive = impl_->snapshots.front().sessions;
    for (const int64_t id : {a, b}) {
        if (std::find(alive.begin(), alive.end(), id) == alive.end()) {
            throw NotFoundError("session " + std::to_string(id) + " is not in this view");
        }
    }
    const std::lock_guard<std::mutex> lock(impl_->catalog);
    change::MapObserver observer(impl_->store);
    const change::Observation before = observer.Session(a), after = observer.Session(b);
    const change::ChangeQuery query;
    const change::ChangeSet changes =
        change::DetectChanges(before, after, impl_->facts.voxel_size_m, query);
    const change::ReportContext context{"session " + std::to_string(a),
                                        "session " + std::to_string(b), impl_->facts.origin,
                                        &query};
    return {{changes.added, changes.removed, after.labels, before.labels},
            json::parse(change::ChangeReportJson(changes, context))};
}

std::optional<ChangeMasks> ViewSource::ChangeSetVoxels(int64_t id) const {
    const auto& records = impl_->change_set_records;
    const auto it = std::find_if(records.begin(), records.end(),
                                 [&](const store::ChangeSetRecord& r) { return r.id == id; });
    if (it == records.end()) throw NotFoundError("no change set " + std::to_string(id));
    const json report = json::parse(it->report, nullptr, false);
    if (report.is_discarded()) return std::nullopt;
    const std::lock_guard<std::mutex> lock(impl_->catalog);
    change::MapObserver observer(impl_->store);
    const auto before = impl_->Side(it->from, it->commit, observer);
    const auto after = impl_->Side(it->to, it->commit, observer);
    if (!before || !after) return std::nullopt;
    const change::ChangeQuery query = QueryOf(report);
    const change::ChangeSet changes =
        change::DetectChanges(*before, *after, impl_->facts.voxel_size_m, query);
    // Only the voxels the record describes: the same counts and objects, or none at all.
    if (changes.added_voxels_total != it->added_voxels ||
        changes.removed_voxels_total != it->removed_voxels ||
        changes.objects.size() != it->objects) {
        return std::nullopt;
    }
    return ChangeMasks{{changes.added, changes.removed, after->labels, before->labels}, report};
}

}  // namespace strata::view
