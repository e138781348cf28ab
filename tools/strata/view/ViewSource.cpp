// The viewer's only use of the map store (ViewSource.hpp): the map opened and its sessions found
// as every command does (pipeline/MapAccess.hpp), snapshots pinned from MapStore (format 5), tiles
// read through store::TileReader (fused grids, each session's layers, the walls and vehicles
// products), the analyses' rows as the store keeps them (ProductHistory), and the saved change
// sets as `strata diff --list` reads them (pipeline::ChangeSetsJson).
#include "ViewSource.hpp"

#include <algorithm>
#include <map>
#include <mutex>
#include <regex>

#include "strata/change/ChangeReport.hpp"
#include "strata/change/MapObserver.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/Diff.hpp"
#include "strata/pipeline/MapAccess.hpp"
#include "strata/store/MapStore.hpp"
#include "strata/store/TileReader.hpp"
#include "strata/vehicles/Vehicles.hpp"
#include "strata/walls/WallReport.hpp"

namespace strata::view {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

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

// A product row as the analysis stored it (its own JSON object), or FormatError naming it.
json RowObject(const store::MapStore& store, const std::string& kind, const store::ProductRow& r) {
    json j = json::parse(r.json, nullptr, false);
    if (!j.is_object()) {
        throw FormatError(store.dir().string() + ": " + kind + " row " + std::to_string(r.id) +
                          " is not a JSON object");
    }
    return j;
}

json XYZ(const json& row, const std::string& x, const std::string& y, const std::string& z) {
    return json::array({row.value(x, 0.0), row.value(y, 0.0), row.value(z, 0.0)});
}

// The rows `strata walls` stores (tools/strata/Walls.cpp), in the shape the page reads.
json WallJson(const json& w, int64_t commit) {
    return {{"commit", commit},
            {"wall_id", w.value("wall_id", 0)},
            {"center", XYZ(w, "center_x", "center_y", "center_z")},
            {"normal", XYZ(w, "normal_x", "normal_y", "normal_z")},
            {"slant_deg", w.value("slant_deg", 0.0)},
            {"uncertainty_deg", w.value("uncertainty_deg", 0.0)},
            {"lean_azimuth_deg", w.value("lean_azimuth_deg", 0.0)},
            {"area_m2", w.value("area_m2", 0.0)},
            {"rms_m", w.value("rms_m", 0.0)},
            {"length_m", w.value("length_m", 0.0)},
            {"height_m", w.value("height_m", 0.0)},
            {"inliers", w.value("inliers", 0)}};
}

// The rows `strata vehicles` stores (tools/strata/Vehicles.cpp).
json VehicleJson(const json& v, int64_t commit) {
    return {{"commit", commit},
            {"vehicle_id", v.value("vehicle_id", 0)},
            {"center", XYZ(v, "center_x", "center_y", "center_z")},
            {"size", XYZ(v, "length_m", "width_m", "height_m")},
            {"yaw_deg", v.value("yaw_deg", 0.0)},
            {"source", v.value("source", "")},
            {"voxels", v.value("voxels", 0)},
            {"cleared_voxels", v.value("cleared_voxels", 0)},
            {"refilled_cells", v.value("refilled_cells", 0)},
            {"refused_cells", v.value("refused_cells", 0)}};
}

template <typename GridT>
typename GridT::ConstPtr Product(const openvdb::GridPtrVec& grids, const char* name) {
    for (const openvdb::GridBase::Ptr& grid : grids) {
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

}  // namespace

struct ViewSource::Impl {
    explicit Impl(store::MapStore opened) : store(std::move(opened)) {}

    store::MapStore store;
    MapFacts facts;
    std::vector<store::Snapshot> pinned;  ///< parallel to snapshots
    std::vector<ViewSnapshot> snapshots;
    /// Reads tiles of each pinned snapshot (parallel to it), sharing one cache-free file reader:
    /// the service keeps its own cache of what it made from the grids.
    std::vector<store::TileReader> readers;
    json sessions = json::array();
    json walls = json::array();
    json vehicles = json::array();
    json change_sets = json::array();    ///< pipeline::ChangeSetsJson's entries up to the commit
    std::map<TileRef, size_t> versions;  ///< every fused version a snapshot names: its reader
    mutable std::mutex catalog;          ///< one catalog reader at a time (change queries)

    void Pin(store::Snapshot snapshot, int64_t as_of_session) {
        ViewSnapshot view{snapshot.commit, as_of_session, {}, {}};
        for (const store::TileVersion& v : snapshot.tiles) {
            const TileRef ref{v.key.x, v.key.y, v.version};
            view.tiles.push_back(ref);
            versions.emplace(ref, pinned.size());
        }
        for (const store::SessionRecord& s : snapshot.sessions) view.sessions.push_back(s.id);
        std::sort(view.sessions.begin(), view.sessions.end());
        snapshots.push_back(std::move(view));
        readers.push_back(readers.empty() ? store::TileReader(store, snapshot, 0)
                                          : readers.front().At(snapshot));
        pinned.push_back(std::move(snapshot));
    }

    // One side of a saved change set, by the name `strata diff` gave it.
    std::optional<change::Observation> Side(const std::string& name, int64_t saved_at,
                                            change::MapObserver& observer) const {
        static const std::regex session(R"(session (\d+))"), as_of(R"(map as of session (\d+))");
        std::smatch m;
        if (std::regex_match(name, m, session)) return observer.Session(std::stoll(m[1]));
        if (std::regex_match(name, m, as_of)) {
            const int64_t id = std::stoll(m[1]);
            for (size_t i = 0; i < pinned.size(); ++i) {
                if (snapshots[i].as_of_session == id) return observer.Map(pinned[i]);
            }
            return std::nullopt;  // a snapshot this view did not pin (or gc dropped)
        }
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
    auto impl = std::make_unique<Impl>(pipeline::OpenMap(dir));
    Impl& s = *impl;
    const store::MapSettings& settings = s.store.settings();
    s.facts = {fs::absolute(dir).lexically_normal().filename().string(), settings.voxel_size_m,
               settings.tile_voxels, settings.origin, settings.format_version};
    if (s.facts.name.empty()) s.facts.name = fs::absolute(dir).parent_path().filename().string();

    // pipeline::SelectSnapshot's choice; the session's id names the snapshot in the page.
    const int64_t as_of_id = as_of.empty() ? 0 : s.store.FindSession(as_of);
    s.Pin(pipeline::SelectSnapshot(s.store, as_of), as_of_id);
    const int64_t commit = s.snapshots.front().commit;
    // The map right after each session, as far as the map keeps its history (strata gc).
    const int64_t history_start = s.store.HistoryStart();
    for (const store::SessionRecord& session :
         std::vector<store::SessionRecord>(s.pinned.front().sessions)) {
        if (session.commit >= history_start) s.Pin(s.store.AsOf(session.id), session.id);
    }
    // Rows newer than the pinned commit belong to a state of the map this viewer does not show.
    for (const auto& [session, removed_by] : s.store.SessionHistory()) {
        if (session.commit <= commit) {
            s.sessions.push_back(SessionJson(session, removed_by > commit ? 0 : removed_by));
        }
    }
    for (const store::ProductRow& r : s.store.ProductRowsAt("walls", commit)) {
        s.walls.push_back(WallJson(RowObject(s.store, "walls", r), r.commit));
    }
    for (const store::ProductRow& r : s.store.ProductRowsAt("vehicles", commit)) {
        s.vehicles.push_back(VehicleJson(RowObject(s.store, "vehicles", r), r.commit));
    }
    for (const json& set : pipeline::ChangeSetsJson(s.store)) {
        if (set.at("commit").get<int64_t>() <= commit) s.change_sets.push_back(set);
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
    const store::TileReader& reader = impl_->readers[it->second];
    const store::TileKey key{ref.x, ref.y};
    const std::shared_ptr<const core::VoxelMap> fused = reader.Fused(key);
    if (!fused) {
        throw NotFoundError("tile " + std::to_string(ref.x) + "_" + std::to_string(ref.y) +
                            " has no fused grids");
    }
    TileGrids grids;
    grids.occupancy = fused->occupancy;
    grids.label = fused->label;
    grids.endpoints = fused->endpoints;
    for (const int64_t session : impl_->snapshots[it->second].sessions) {
        if (const auto layer = reader.Layers(key, session)) {
            grids.sessions.emplace_back(session, layer->occupied);
            grids.sessions_free.emplace_back(session, layer->free);
        }
    }
    const openvdb::GridPtrVec wall_grids = reader.Products(key, "walls");
    const openvdb::GridPtrVec car_grids = reader.Products(key, "vehicles");
    grids.slant_deg = Product<openvdb::FloatGrid>(wall_grids, walls::product_names::kSlantDeg);
    grids.wall_id = Product<openvdb::Int32Grid>(wall_grids, walls::product_names::kWallId);
    grids.cleared = Product<openvdb::Int32Grid>(car_grids, vehicles::grid_names::kCleared);
    grids.refilled = Product<openvdb::FloatGrid>(car_grids, vehicles::grid_names::kRefilled);
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
    const json& sets = impl_->change_sets;
    const auto it =
        std::find_if(sets.begin(), sets.end(), [&](const json& set) { return set.at("id") == id; });
    if (it == sets.end()) throw NotFoundError("no change set " + std::to_string(id));
    const json report = it->value("report", json());
    if (!report.is_object()) return std::nullopt;
    const auto commit = it->at("commit").get<int64_t>();
    const std::lock_guard<std::mutex> lock(impl_->catalog);
    change::MapObserver observer(impl_->store);
    const auto before = impl_->Side(it->value("from", ""), commit, observer);
    const auto after = impl_->Side(it->value("to", ""), commit, observer);
    if (!before || !after) return std::nullopt;
    const change::ChangeQuery query = QueryOf(report);
    const change::ChangeSet changes =
        change::DetectChanges(*before, *after, impl_->facts.voxel_size_m, query);
    // Only the voxels the record describes: the same counts and objects, or none at all.
    if (changes.added_voxels_total != it->value("added_voxels", size_t{0}) ||
        changes.removed_voxels_total != it->value("removed_voxels", size_t{0}) ||
        changes.objects.size() != it->value("objects", size_t{0})) {
        return std::nullopt;
    }
    return ChangeMasks{{changes.added, changes.removed, after->labels, before->labels}, report};
}

}  // namespace strata::view
