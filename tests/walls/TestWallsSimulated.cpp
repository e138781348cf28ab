// The wall pipeline scored against the simulator's ground truth: the street scene
// (datasets/scenes/street.json) has the five wall kinds of the wall-slant study with slants of
// 86 to 90 degrees, trees and bushes in front of the facades, and 2 cm range noise. Prints the
// per-wall table docs/walls.md shows.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "TempPath.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/sim/SimulateScene.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::walls {
namespace {

namespace fs = std::filesystem;

// Voxel sizes the street is mapped at (the store's default and a finer one).
const std::vector<double> kVoxelSizes = {0.2, 0.1};
// The targets are 0.3 deg mean and 1.0 deg max; these bounds are 2-3x what the default
// pipeline measures (0.2 m: 0.049 / 0.093 deg, 0.1 m: 0.071 / 0.196 deg), so losing the robust
// fit (least squares: 0.51 deg max at 0.2 m) fails them.
struct SlantBounds {
    double mean_deg, max_deg;
};
SlantBounds BoundsFor(double voxel) {
    return voxel > 0.15 ? SlantBounds{0.12, 0.25} : SlantBounds{0.18, 0.5};
}
// street.json's walls longer than kMinTruthLengthM: every one must be found.
constexpr size_t kTruthWalls = 10;
// Vegetation parts the pipeline sees (measured 8 at 0.2 m, 14 at 0.1 m): at least this many, so
// "no tree taken for a wall" is not vacuous.
constexpr size_t kMinVegetationParts = 4;
// Walls the targets count: longer than this.
constexpr double kMinTruthLengthM = 3.0;
// A detected wall's voxel is on a truth wall when this close to its plane and inside its front
// polygon grown by the same margin; a wall is found by the detection with most such voxels,
// when it has at least kMinMatchVoxels of them and normals agree within kMaxMatchAngleDeg.
constexpr double kMatchDistanceM = 0.3;
constexpr size_t kMinMatchVoxels = 20;
constexpr double kMaxMatchAngleDeg = 10.0;

struct TruthWall {
    int id = 0;
    std::string name, kind;
    double slant_deg = 90.0;
    Eigen::Vector3d normal;
    double d = 0.0;
    Eigen::Vector3d origin, u, v;  // polygon corner 0 and the edges to corners 1 and 3
    [[nodiscard]] double length() const { return u.norm(); }
    [[nodiscard]] bool Holds(const Eigen::Vector3d& p) const {
        if (std::abs(normal.dot(p) + d) > kMatchDistanceM) return false;
        const Eigen::Vector3d q = p - origin;
        const double a = q.dot(u.normalized()), b = q.dot(v.normalized());
        return a >= -kMatchDistanceM && a <= u.norm() + kMatchDistanceM && b >= -kMatchDistanceM &&
               b <= v.norm() + kMatchDistanceM;
    }
};

struct Simulated {
    std::map<double, core::VoxelMap> maps;  // by voxel size
    std::vector<TruthWall> truth;
};

const Simulated& Street() {
    static const fs::path temp = strata::test::TempPath("walls_sim");
    static const Simulated scene = [] {
        Simulated s;
        fs::remove_all(temp);
        sim::SimulateConfig config;
        config.write_picture = false;
        (void)sim::SimulateSceneToSequence(
            fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/street.json", temp, config);
        const io::KittiSequence seq = io::OpenKittiSequence(temp);
        for (double voxel : kVoxelSizes) s.maps.emplace(voxel, core::VoxelMap::Create(voxel));
        for (size_t i = 0; i < seq.size(); ++i) {
            const core::Scan scan = io::ReadKittiScan(seq, i);
            for (auto& [voxel, map] : s.maps) integration::Integrator(map, {}).Integrate(scan);
        }

        std::ifstream in(temp / "ground_truth.json");
        const nlohmann::json j = nlohmann::json::parse(in);
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
            s.truth.push_back(t);
        }
        return s;
    }();
    return scene;
}

struct Match {
    const TruthWall* truth = nullptr;
    const Wall* wall = nullptr;  // null when not found
    size_t voxels = 0;
};

std::vector<Match> MatchWalls(const Simulated& s, const core::VoxelMap& map,
                              const WallResult& result) {
    std::vector<Match> matches;
    for (const TruthWall& t : s.truth) {
        Match m{&t, nullptr, 0};
        for (const Wall& w : result.walls) {
            if (std::abs(w.normal.dot(t.normal)) < std::cos(kMaxMatchAngleDeg * M_PI / 180.0)) {
                continue;
            }
            size_t on = 0;
            for (const auto& c : w.voxels) on += t.Holds(map.VoxelCenter(c));
            if (on >= kMinMatchVoxels && on > m.voxels) {
                m.wall = &w;
                m.voxels = on;
            }
        }
        matches.push_back(m);
    }
    return matches;
}

struct Score {
    size_t counted = 0, found = 0, vegetation = 0, vegetation_as_wall = 0;
    double mean_error = 0.0, max_error = 0.0;
};

// Scores one run; `table` prints the per-wall rows docs/walls.md shows.
Score Evaluate(const Simulated& s, const core::VoxelMap& map, const WallResult& result,
               bool table) {
    const std::vector<Match> matches = MatchWalls(s, map, result);
    if (table) {
        std::printf(
            "| wall | kind | truth slant | found slant | error | uncertainty (1 sigma) | "
            "inliers | rms m |\n|---|---|---|---|---|---|---|---|\n");
    }
    Score score;
    double sum_error = 0.0;
    for (const Match& m : matches) {
        if (m.truth->length() < kMinTruthLengthM) continue;
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
    for (const WallPart& p : result.parts) {
        if (p.dominant_class != core::SemanticClass::kVegetation) continue;
        ++score.vegetation;
        score.vegetation_as_wall += p.verdict == PartVerdict::kWall;
    }
    score.mean_error = score.found ? sum_error / static_cast<double>(score.found) : 0.0;
    return score;
}

class WallsSimulated : public ::testing::TestWithParam<double> {};

TEST_P(WallsSimulated, StreetSlantsWithinTheTargets) {
    const double voxel = GetParam();
    const Simulated& s = Street();
    const core::VoxelMap& map = s.maps.at(voxel);
    const WallResult result = FindWalls(map);
    std::printf("voxel %.2f m:\n", voxel);
    const Score score = Evaluate(s, map, result, true);
    std::printf(
        "walls found %zu of %zu; mean slant error %.3f deg, max %.3f deg; vegetation "
        "parts taken as walls %zu of %zu; %zu walls reported; %.2f s\n",
        score.found, score.counted, score.mean_error, score.max_error, score.vegetation_as_wall,
        score.vegetation, result.walls.size(),
        result.stats.seconds_columns + result.stats.seconds_clustering +
            result.stats.seconds_fitting);
    EXPECT_EQ(score.counted, kTruthWalls) << "the ground truth's walls";
    EXPECT_EQ(score.found, kTruthWalls);
    EXPECT_LE(score.mean_error, BoundsFor(voxel).mean_deg);
    EXPECT_LE(score.max_error, BoundsFor(voxel).max_deg);
    EXPECT_GE(score.vegetation, kMinVegetationParts) << "the street's trees and bushes";
    EXPECT_EQ(score.vegetation_as_wall, 0u);

    // What each refinement buys (printed for docs/walls.md; the targets are asserted above).
    struct Variant {
        const char* name;
        WallConfig config;
    };
    std::vector<Variant> variants(3);
    variants[0].name = "voxel centres, no refinement (the study's pipeline on a voxel map)";
    variants[0].config.use_point_means = false;
    variants[0].config.refine = false;
    variants[1].name = "voxel centres";
    variants[1].config.use_point_means = false;
    variants[2].name = "point means, no robust refinement";
    variants[2].config.refine = false;
    std::printf("| variant | found | mean error | max error |\n|---|---|---|---|\n");
    for (const Variant& v : variants) {
        const Score sc = Evaluate(s, map, FindWalls(map, v.config), false);
        std::printf("| %s | %zu of %zu | %.2f | %.2f |\n", v.name, sc.found, sc.counted,
                    sc.mean_error, sc.max_error);
    }
}

INSTANTIATE_TEST_SUITE_P(VoxelSizes, WallsSimulated, ::testing::ValuesIn(kVoxelSizes),
                         [](const ::testing::TestParamInfo<double>& param) {
                             return "voxel_" +
                                    std::to_string(
                                        static_cast<int>(std::lround(param.param * 100))) +
                                    "cm";
                         });

}  // namespace
}  // namespace strata::walls
