// What one WallAssembler hands another (rank 0 takes the other ranks', docs/scale.md "Walls"):
// its counts, judged parts, waiting pieces and fitted walls, each record with every field it
// has (core/Bytes.hpp names them once for both directions; keys are plain values).
#include "Handover.hpp"

#include "strata/core/Bytes.hpp"

namespace strata::core {

template <>
struct Fields<walls::WallStats> {
    template <typename Io, typename S>
    static void Visit(Io& io, S& s) {
        io(s.occupied_columns, s.voting_columns, s.candidate_voxels, s.clusters, s.noise_voxels,
           s.seconds_columns, s.seconds_clustering, s.seconds_fitting);
    }
};

template <>
struct Fields<walls::WallPart> {
    template <typename Io, typename P>
    static void Visit(Io& io, P& p) {
        io(p.cluster, p.voxels, p.inliers, p.eigen_ratio, p.slant_deg, p.height_m, p.length_m,
           p.centroid, p.dominant_class, p.verdict);
    }
};

template <>
struct Fields<walls::detail::Piece> {
    template <typename Io, typename P>
    static void Visit(Io& io, P& p) {
        io(p.plane.normal, p.plane.d, p.centroid, p.lo, p.hi, p.voxels, p.points, p.inliers);
    }
};

template <>
struct Fields<walls::Wall> {
    template <typename Io, typename W>
    static void Visit(Io& io, W& w) {
        io(w.id, w.slant_deg, w.slant_to_ground_deg, w.centroid, w.normal, w.d, w.inliers,
           w.area_m2, w.rms_m, w.uncertainty_deg, w.lean_azimuth_deg, w.length_m, w.height_m,
           w.eigen_ratio, w.parts, w.voxels);
    }
};

}  // namespace strata::core

namespace strata::walls::detail {
namespace {

template <typename T>
void Append(std::vector<T>& to, std::vector<T>&& from) {
    to.insert(to.end(), std::make_move_iterator(from.begin()), std::make_move_iterator(from.end()));
}

}  // namespace

std::string EncodeHandover(const WallStats& stats,
                           const std::vector<std::pair<PartKey, WallPart>>& parts,
                           const std::vector<std::pair<PartKey, Piece>>& pieces,
                           const std::vector<std::pair<PartKey, Wall>>& walls) {
    std::string out;
    core::Put(out, stats);
    core::Put(out, parts);
    core::Put(out, pieces);
    core::Put(out, walls);
    return out;
}

void DecodeHandover(const std::string& bytes, WallStats& stats,
                    std::vector<std::pair<PartKey, WallPart>>& parts,
                    std::vector<std::pair<PartKey, Piece>>& pieces,
                    std::vector<std::pair<PartKey, Wall>>& walls) {
    core::ByteReader in(bytes, "walls");
    // The counts of the stages an assembler runs; the columns' are WallsKept's.
    const auto theirs = in.Get<WallStats>();
    stats.candidate_voxels += theirs.candidate_voxels;
    stats.clusters += theirs.clusters;
    stats.noise_voxels += theirs.noise_voxels;
    stats.seconds_clustering += theirs.seconds_clustering;
    stats.seconds_fitting += theirs.seconds_fitting;
    Append(parts, in.Get<std::vector<std::pair<PartKey, WallPart>>>());
    Append(pieces, in.Get<std::vector<std::pair<PartKey, Piece>>>());
    Append(walls, in.Get<std::vector<std::pair<PartKey, Wall>>>());
}

}  // namespace strata::walls::detail
