#include "WallEval.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

namespace strata::testing {

bool TruthWall::Holds(const Eigen::Vector3d& p) const {
    if (std::abs(normal.dot(p) + d) > kWallMatchDistanceM) return false;
    const Eigen::Vector3d q = p - origin;
    const double a = q.dot(u.normalized()), b = q.dot(v.normalized());
    return a >= -kWallMatchDistanceM && a <= u.norm() + kWallMatchDistanceM &&
           b >= -kWallMatchDistanceM && b <= v.norm() + kWallMatchDistanceM;
}

std::vector<TruthWall> ReadTruthWalls(const std::filesystem::path& ground_truth) {
    std::ifstream in(ground_truth);
    const nlohmann::json j = nlohmann::json::parse(in);
    std::vector<TruthWall> walls;
    for (const auto& w : j.at("walls")) {
        TruthWall t;
        t.id = w.at("id");
        t.name = w.at("name");
        t.kind = w.at("kind");
        t.slant_deg = w.at("slant_deg");
        const auto& plane = w.at("plane");
        t.normal = Eigen::Vector3d(plane[0], plane[1], plane[2]);
        t.d = plane[3];
        std::vector<Eigen::Vector3d> corners;
        for (const auto& c : w.at("polygon")) corners.emplace_back(c[0], c[1], c[2]);
        t.origin = corners[0];
        t.u = corners[1] - corners[0];
        t.v = corners[3] - corners[0];
        walls.push_back(t);
    }
    return walls;
}

std::vector<WallMatch> MatchWalls(const std::vector<TruthWall>& truth, const core::VoxelMap& map,
                                  const walls::WallResult& result) {
    std::vector<WallMatch> matches;
    for (const TruthWall& t : truth) {
        WallMatch m{&t, nullptr, 0};
        for (const walls::Wall& w : result.walls) {
            if (std::abs(w.normal.dot(t.normal)) < std::cos(kMaxWallMatchDeg * M_PI / 180.0)) {
                continue;
            }
            size_t on = 0;
            for (const auto& c : w.voxels) on += t.Holds(map.VoxelCenter(c));
            if (on >= kMinWallMatchVoxels && on > m.voxels) {
                m.wall = &w;
                m.voxels = on;
            }
        }
        matches.push_back(m);
    }
    return matches;
}

WallScore ScoreWalls(const std::vector<TruthWall>& truth, const core::VoxelMap& map,
                     const walls::WallResult& result, bool table) {
    const std::vector<WallMatch> matches = MatchWalls(truth, map, result);
    if (table) {
        std::printf(
            "| wall | kind | truth slant | found slant | error | uncertainty (1 sigma) | "
            "inliers | rms m |\n|---|---|---|---|---|---|---|---|\n");
    }
    WallScore score;
    double sum_error = 0.0;
    for (const WallMatch& m : matches) {
        if (m.truth->length() < kMinTruthWallLengthM) continue;
        ++score.counted;
        if (!m.wall) {
            if (table) {
                std::printf("| %s | %s | %.2f | not found | | | | |\n", m.truth->name.c_str(),
                            m.truth->kind.c_str(), m.truth->slant_deg);
            }
            continue;
        }
        ++score.found;
        const double error = std::abs(m.wall->slant_deg - m.truth->slant_deg);
        sum_error += error;
        score.max_error = std::max(score.max_error, error);
        if (table) {
            std::printf("| %s | %s | %.2f | %.2f | %.2f | %.2f | %zu | %.3f |\n",
                        m.truth->name.c_str(), m.truth->kind.c_str(), m.truth->slant_deg,
                        m.wall->slant_deg, error, m.wall->uncertainty_deg, m.wall->inliers,
                        m.wall->rms_m);
        }
    }
    for (const walls::WallPart& p : result.parts) {
        if (p.dominant_class != core::SemanticClass::kVegetation) continue;
        ++score.vegetation;
        score.vegetation_as_wall += p.verdict == walls::PartVerdict::kWall;
    }
    score.mean_error = score.found ? sum_error / static_cast<double>(score.found) : 0.0;
    return score;
}

}  // namespace strata::testing
