// What one WallAssembler hands another (rank 0 takes the other ranks', docs/scale.md "Walls"):
// its counts, judged parts, waiting pieces and fitted walls as plain records.
#include "Handover.hpp"

#include <cstdint>

#include "strata/core/Bytes.hpp"

namespace strata::walls::detail {
namespace {

// The records (plain values: Eigen's vectors as three doubles).
struct FlatKey {
    int32_t x, y, z, part;
};
struct Flat3 {
    double x, y, z;
};
struct FlatPart {
    FlatKey key;
    int32_t verdict, dominant_class;
    uint64_t voxels, inliers;
    double eigen_ratio, slant_deg, height_m, length_m;
    Flat3 centroid;
};
struct FlatPiece {
    FlatKey key;
    Flat3 normal, centroid, lo, hi;
    double d;
    uint64_t inliers;
};
struct FlatWall {
    FlatKey key;
    Flat3 centroid, normal;
    double slant_deg, d, area_m2, rms_m, uncertainty_deg, lean_azimuth_deg, length_m, height_m,
        eigen_ratio;
    uint64_t inliers;
    int32_t parts;
};

FlatKey Flat(const PartKey& k) { return {k.cluster.x(), k.cluster.y(), k.cluster.z(), k.part}; }
PartKey Unflat(const FlatKey& k) { return {openvdb::Coord(k.x, k.y, k.z), k.part}; }
Flat3 Flat(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
Eigen::Vector3d Unflat(const Flat3& v) { return {v.x, v.y, v.z}; }

}  // namespace

std::string EncodeHandover(const WallStats& stats,
                           const std::vector<std::pair<PartKey, WallPart>>& parts,
                           const std::vector<std::pair<PartKey, Piece>>& pieces,
                           const std::vector<std::pair<PartKey, Wall>>& walls) {
    std::string out;
    core::Put(out, stats.candidate_voxels);
    core::Put(out, stats.clusters);
    core::Put(out, stats.noise_voxels);
    core::Put(out, stats.seconds_clustering);
    core::Put(out, stats.seconds_fitting);
    std::vector<FlatPart> flat;
    for (const auto& [key, p] : parts) {
        flat.push_back({Flat(key), static_cast<int32_t>(p.verdict),
                        static_cast<int32_t>(p.dominant_class), p.voxels, p.inliers, p.eigen_ratio,
                        p.slant_deg, p.height_m, p.length_m, Flat(p.centroid)});
    }
    core::PutVector(out, flat);
    core::Put(out, static_cast<uint64_t>(pieces.size()));
    for (const auto& [key, p] : pieces) {
        core::Put(out, FlatPiece{Flat(key), Flat(p.plane.normal), Flat(p.centroid), Flat(p.lo),
                                 Flat(p.hi), p.plane.d, p.inliers});
        core::PutVector(out, p.voxels);
        std::vector<Flat3> points;
        for (const auto& q : p.points) points.push_back(Flat(q));
        core::PutVector(out, points);
    }
    core::Put(out, static_cast<uint64_t>(walls.size()));
    for (const auto& [key, w] : walls) {
        core::Put(out, FlatWall{Flat(key), Flat(w.centroid), Flat(w.normal), w.slant_deg, w.d,
                                w.area_m2, w.rms_m, w.uncertainty_deg, w.lean_azimuth_deg,
                                w.length_m, w.height_m, w.eigen_ratio, w.inliers, w.parts});
        core::PutVector(out, w.voxels);
    }
    return out;
}

void DecodeHandover(const std::string& bytes, WallStats& stats,
                    std::vector<std::pair<PartKey, WallPart>>& parts,
                    std::vector<std::pair<PartKey, Piece>>& pieces,
                    std::vector<std::pair<PartKey, Wall>>& walls) {
    core::ByteReader in(bytes, "walls");
    stats.candidate_voxels += in.Get<size_t>();
    stats.clusters += in.Get<size_t>();
    stats.noise_voxels += in.Get<size_t>();
    stats.seconds_clustering += in.Get<double>();
    stats.seconds_fitting += in.Get<double>();
    for (const FlatPart& f : in.GetVector<FlatPart>()) {
        WallPart p;
        p.verdict = static_cast<PartVerdict>(f.verdict);
        p.dominant_class = static_cast<core::SemanticClass>(f.dominant_class);
        p.voxels = f.voxels;
        p.inliers = f.inliers;
        p.eigen_ratio = f.eigen_ratio;
        p.slant_deg = f.slant_deg;
        p.height_m = f.height_m;
        p.length_m = f.length_m;
        p.centroid = Unflat(f.centroid);
        parts.emplace_back(Unflat(f.key), p);
    }
    for (auto n = in.Get<uint64_t>(); n > 0; --n) {
        const auto f = in.Get<FlatPiece>();
        Piece p;
        p.plane = {Unflat(f.normal), f.d};
        p.centroid = Unflat(f.centroid);
        p.lo = Unflat(f.lo);
        p.hi = Unflat(f.hi);
        p.inliers = f.inliers;
        p.voxels = in.GetVector<openvdb::Coord>();
        for (const Flat3& q : in.GetVector<Flat3>()) p.points.push_back(Unflat(q));
        pieces.emplace_back(Unflat(f.key), std::move(p));
    }
    for (auto n = in.Get<uint64_t>(); n > 0; --n) {
        const auto f = in.Get<FlatWall>();
        Wall w;
        w.centroid = Unflat(f.centroid);
        w.normal = Unflat(f.normal);
        w.slant_deg = f.slant_deg;
        w.d = f.d;
        w.area_m2 = f.area_m2;
        w.rms_m = f.rms_m;
        w.uncertainty_deg = f.uncertainty_deg;
        w.lean_azimuth_deg = f.lean_azimuth_deg;
        w.length_m = f.length_m;
        w.height_m = f.height_m;
        w.eigen_ratio = f.eigen_ratio;
        w.inliers = f.inliers;
        w.parts = f.parts;
        w.voxels = in.GetVector<openvdb::Coord>();
        walls.emplace_back(Unflat(f.key), std::move(w));
    }
}

}  // namespace strata::walls::detail
