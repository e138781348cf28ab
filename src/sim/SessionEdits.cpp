#include "SessionEdits.hpp"

#include <algorithm>
#include <cmath>

#include "MeshBuilders.hpp"
#include "ObjectGeometry.hpp"
#include "WallGeometry.hpp"
#include "strata/core/Error.hpp"

namespace strata::sim::detail {
namespace {

EditTruth Truth(const ObjectSpec& object, const char* change, const char* kind) {
    return {ObjectBox(object), change, kind};
}

// Moves a movable object so that its footprint centre lands on `to` (z = ground there).
void MoveObject(ObjectSpec& o, const Eigen::Vector3d& to, double yaw_deg, const std::string& at) {
    const auto keep = [](double old, double fresh) { return std::isnan(fresh) ? old : fresh; };
    if (auto* v = std::get_if<VehicleSpec>(&o.shape)) {
        v->center = to;
        v->yaw_deg = keep(v->yaw_deg, yaw_deg);
    } else if (auto* b = std::get_if<BoxSpec>(&o.shape)) {
        b->center = to + Eigen::Vector3d(0, 0, 0.5 * b->size.z());
        b->yaw_deg = keep(b->yaw_deg, yaw_deg);
    } else if (auto* p = std::get_if<PlantSpec>(&o.shape)) {
        p->base = to;
    } else if (auto* pole = std::get_if<PoleSpec>(&o.shape)) {
        pole->base = to;
    } else {
        throw FormatError(at + ": only vehicles, boxes, plants and poles can move");
    }
}

}  // namespace

SessionObjects ApplySessionEdits(const SceneSpec& spec, size_t session) {
    if (session >= spec.sessions.size()) {
        throw FormatError(spec.source + ": no session " + std::to_string(session));
    }
    SessionObjects out;
    out.objects = spec.objects;
    for (size_t s = 0; s <= session; ++s) {
        const bool record = s == session;
        for (const EditSpec& e : spec.sessions[s].edits) {
            const std::string at = spec.source + ": session '" + spec.sessions[s].name + "'";
            const auto it = std::find_if(out.objects.begin(), out.objects.end(),
                                         [&](const ObjectSpec& o) { return o.name == e.object; });
            if (e.kind == EditSpec::Kind::kAdd) {
                if (it != out.objects.end()) {
                    throw FormatError(at + ": object '" + e.object + "' already exists");
                }
                out.objects.push_back(*e.added);
                if (record) out.edits.push_back(Truth(*e.added, "added", "add"));
                continue;
            }
            if (it == out.objects.end()) {
                throw FormatError(at + ": edit of unknown object '" + e.object + "'");
            }
            ObjectSpec& o = *it;
            if (e.kind == EditSpec::Kind::kRemove) {
                if (record) out.edits.push_back(Truth(o, "removed", "remove"));
                out.objects.erase(it);
            } else if (e.kind == EditSpec::Kind::kMove) {
                if (record) out.edits.push_back(Truth(o, "removed", "move"));
                MoveObject(o, e.center, e.yaw_deg, at);
                if (record) out.edits.push_back(Truth(o, "added", "move"));
            } else if (e.kind == EditSpec::Kind::kDemolish) {
                auto* w = std::get_if<WallSpec>(&o.shape);
                if (w == nullptr) throw FormatError(at + ": only walls are demolished");
                // A full-height cut through the wall over [u0, u1].
                w->openings.push_back({e.u0, e.u1, -1.0, w->height_m + 1.0, -1.0});
                const WallFrame frame(*w);
                const double um = 0.5 * (e.u0 + e.u1);
                const Eigen::Vector2d d = frame.Direction(um);
                EditTruth t;
                t.box.id = o.id;
                t.box.name = o.name;
                t.box.type = "wall_segment";
                t.box.center = frame.At(um, 0.5 * w->height_m, 0.5 * w->thickness_m);
                t.box.size = Eigen::Vector3d(e.u1 - e.u0, w->thickness_m, w->height_m);
                t.box.yaw_deg = RadToDeg(std::atan2(d.y(), d.x()));
                t.change = "removed";
                t.kind = "demolish";
                if (record) out.edits.push_back(t);
            } else if (e.kind == EditSpec::Kind::kGrow) {
                auto* p = std::get_if<PlantSpec>(&o.shape);
                if (p == nullptr) throw FormatError(at + ": only plants grow");
                if (!p->tree) p->crown_center_height_m *= e.scale;  // a bush stays on the ground
                p->crown_radii *= e.scale;
                if (record) out.edits.push_back(Truth(o, "added", "grow"));
            }
        }
    }
    return out;
}

}  // namespace strata::sim::detail

namespace strata::sim {

std::vector<ObjectSpec> ObjectsOfSession(const SceneSpec& spec, size_t session) {
    return detail::ApplySessionEdits(spec, session).objects;
}

}  // namespace strata::sim
