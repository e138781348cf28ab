#include "ChangeEval.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

namespace strata::testing {
namespace {

using openvdb::BoolGrid;
using openvdb::Coord;

Coord VoxelOf(const Eigen::Vector3d& p, double voxel) {
    return Coord(static_cast<int>(std::floor(p.x() / voxel)),
                 static_cast<int>(std::floor(p.y() / voxel)),
                 static_cast<int>(std::floor(p.z() / voxel)));
}

// The voxels of an edit a perfect detector would report: voxels holding points of the edited
// object (inside its box) that the map of the side where it is present holds occupied and the
// other side's map holds free (voxels the other side never observed are unknown by definition).
// `strict` also leaves out voxels the other side's points hit (a voxel holding the car in one
// session and the road under it in the other, which that map calls free after more rays passed).
BoolGrid::Ptr TruthVoxels(const ChangeCase& c, const TruthEdit& e, bool strict) {
    const bool added = e.change == "added";
    const SessionHits& present = added ? c.hits_b : c.hits_a;
    const SessionHits& other_hits = added ? c.hits_a : c.hits_b;
    const change::Observation& other = added ? c.a : c.b;
    BoolGrid::Ptr out = BoolGrid::create(false);
    const auto it = present.by_object.find(e.object);
    if (it == present.by_object.end()) return out;
    auto acc = out->getAccessor();
    for (const Eigen::Vector3d& p : it->second) {
        if (e.Contains(p, kEditBoxMarginM)) acc.setValueOn(VoxelOf(p, c.voxel), true);
    }
    out->topologyIntersection(*other.masks.free);
    out->topologyIntersection(*(added ? c.b : c.a).masks.occupied);
    if (strict) out->topologyDifference(*other_hits.all);
    return out;
}

size_t Overlap(const BoolGrid& x, const BoolGrid& y) {
    BoolGrid::Ptr both = x.deepCopy();
    both->topologyIntersection(y);
    return both->activeVoxelCount();
}

}  // namespace

bool TruthEdit::Contains(const Eigen::Vector3d& p, double margin) const {
    const double y = yaw_deg * M_PI / 180.0;
    const Eigen::Vector3d d = p - center;
    const double u = std::cos(y) * d.x() + std::sin(y) * d.y();
    const double v = -std::sin(y) * d.x() + std::cos(y) * d.y();
    return std::abs(u) <= size.x() / 2 + margin && std::abs(v) <= size.y() / 2 + margin &&
           std::abs(d.z()) <= size.z() / 2 + margin;
}

std::vector<TruthEdit> ReadTruthEdits(const std::filesystem::path& ground_truth) {
    std::ifstream in(ground_truth);
    const nlohmann::json j = nlohmann::json::parse(in);
    std::vector<TruthEdit> edits;
    for (const auto& e : j.at("edits")) {
        TruthEdit edit;
        edit.object = e.at("object");
        edit.name = e.at("name");
        edit.change = e.at("change");
        edit.kind = e.at("kind");
        for (int k = 0; k < 3; ++k) {
            edit.center[k] = e.at("center")[k];
            edit.size[k] = e.at("size")[k];
        }
        edit.yaw_deg = e.at("yaw_deg");
        edits.push_back(edit);
    }
    return edits;
}

void AddSessionHits(SessionHits& hits, const core::Scan& scan, const std::set<int>& objects,
                    double voxel) {
    auto acc = hits.all->getAccessor();
    for (size_t p = 0; p < scan.points.size(); ++p) {
        const Eigen::Vector3d w = scan.T_world_sensor * scan.points[p];
        acc.setValueOn(VoxelOf(w, voxel), true);
        const int id = scan.instances.empty() ? 0 : scan.instances[p];
        if (objects.count(id)) hits.by_object[id].push_back(w);
    }
}

SessionHits ReadSessionHits(const io::KittiSequence& seq, const std::set<int>& objects,
                            double voxel) {
    SessionHits hits;
    for (size_t i = 0; i < seq.size(); ++i) {
        AddSessionHits(hits, io::ReadKittiScan(seq, i), objects, voxel);
    }
    return hits;
}

ChangeScore ScoreChanges(const ChangeCase& c, const change::ChangeQuery& query, bool strict,
                         bool table) {
    const change::ChangeSet changes = change::DetectChanges(c.a, c.b, c.voxel, query);
    const auto centre = [&c](const Coord& v) -> Eigen::Vector3d {
        return (Eigen::Vector3d(v.x(), v.y(), v.z()) + Eigen::Vector3d::Constant(0.5)) * c.voxel;
    };
    const auto object_voxels = [&](const change::ChangeObject& o) {
        const BoolGrid& all =
            o.kind == change::ChangeKind::kAdded ? *changes.added : *changes.removed;
        std::vector<Coord> voxels;
        for (auto on = all.cbeginValueOn(); on; ++on) {
            const Eigen::Vector3d p = centre(on.getCoord());
            if ((p.array() >= o.bbox_min.array()).all() && (p.array() <= o.bbox_max.array()).all())
                voxels.push_back(on.getCoord());
        }
        return voxels;
    };
    std::map<size_t, size_t> matched;  // edit -> number of objects
    size_t true_objects = 0;
    for (const change::ChangeObject& o : changes.objects) {
        int best = -1;
        size_t best_inside = 0;
        const std::vector<Coord> voxels = object_voxels(o);
        for (size_t e = 0; e < c.edits.size(); ++e) {
            if (c.edits[e].change != change::ChangeKindName(o.kind)) continue;
            size_t inside = 0;
            for (const Coord& v : voxels) {
                inside += c.edits[e].Contains(centre(v), kEditBoxMarginM + c.voxel) ? 1 : 0;
            }
            if (inside > best_inside) {
                best_inside = inside;
                best = static_cast<int>(e);
            }
        }
        if (best >= 0 && 2 * best_inside > voxels.size()) {
            ++true_objects;
            ++matched[static_cast<size_t>(best)];
        } else if (table) {
            std::printf("[ change ] false object %d: %s, %zu voxels at (%.1f, %.1f, %.1f), %s\n",
                        o.id, change::ChangeKindName(o.kind), o.voxels, o.centroid.x(),
                        o.centroid.y(), o.centroid.z(), core::ClassName(o.dominant_class));
        }
    }
    ChangeScore score;
    score.objects = changes.objects.size();
    size_t found = 0, inter_sum = 0, union_sum = 0;
    if (table)
        std::printf("[ change ] | edit | change | truth voxels | detected | IoU | objects |\n");
    for (size_t e = 0; e < c.edits.size(); ++e) {
        const TruthEdit& edit = c.edits[e];
        const BoolGrid::Ptr truth = TruthVoxels(c, edit, strict);
        const BoolGrid& all = edit.change == "added" ? *changes.added : *changes.removed;
        BoolGrid::Ptr detected = BoolGrid::create(false);
        for (auto on = all.cbeginValueOn(); on; ++on) {
            if (edit.Contains(centre(on.getCoord()), kEditBoxMarginM + c.voxel)) {
                detected->tree().setValueOn(on.getCoord(), true);
            }
        }
        const size_t t = truth->activeVoxelCount(), d = detected->activeVoxelCount();
        const size_t inter = Overlap(*truth, *detected);
        const size_t uni = t + d - inter;
        if (t >= kMinObservableVoxels) {
            ++score.observable;
            found += matched.count(e) ? 1 : 0;
            inter_sum += inter;
            union_sum += uni;
        }
        if (table) {
            std::printf("[ change ] | %s (%s) | %s | %zu | %zu | %.3f | %zu |\n", edit.name.c_str(),
                        edit.kind.c_str(), edit.change.c_str(), t, d,
                        uni ? static_cast<double>(inter) / uni : 1.0,
                        matched.count(e) ? matched.at(e) : size_t{0});
        }
    }
    score.precision =
        changes.objects.empty() ? 1.0 : static_cast<double>(true_objects) / changes.objects.size();
    score.recall = score.observable ? static_cast<double>(found) / score.observable : 1.0;
    score.iou = union_sum ? static_cast<double>(inter_sum) / union_sum : 1.0;
    return score;
}

}  // namespace strata::testing
