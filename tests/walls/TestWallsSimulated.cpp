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

#include "strata/integration/Integrator.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/sim/SimulateScene.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::walls {
namespace {

namespace fs = std::filesystem;

constexpr double kVoxel = 0.2;
// The targets.
constexpr double kMaxMeanSlantErrorDeg = 0.3;
constexpr double kMaxSlantErrorDeg = 1.0;
constexpr double kMinFoundFraction = 0.95;
constexpr double kMaxVegetationAsWall = 0.05;
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
    core::VoxelMap map;
    std::vector<TruthWall> truth;
    std::map<int, std::vector<Eigen::Vector3d>> points_of;  // simulated points by object id
};

struct TempDir {
    fs::path path = fs::temp_directory_path() / ("strata_walls_sim_" + std::to_string(::getpid()));
    ~TempDir() {
        std::error_code ignored;
        fs::remove_all(path, ignored);
    }
};

const Simulated& Street() {
    static const TempDir temp;
    static const Simulated scene = [] {
        Simulated s;
        fs::remove_all(temp.path);
        sim::SimulateConfig config;
        config.write_picture = false;
        (void)sim::SimulateSceneToSequence(
            fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/street.json", temp.path, config);
        const io::KittiSequence seq = io::OpenKittiSequence(temp.path);
        s.map = core::VoxelMap::Create(kVoxel);
        integration::Integrator integrator(s.map, {});
        for (size_t i = 0; i < seq.size(); ++i) {
            const core::Scan scan = io::ReadKittiScan(seq, i);
            integrator.Integrate(scan);
            for (size_t p = 0; p < scan.points.size(); ++p) {
                if (!scan.instances.empty() && scan.instances[p] != 0) {
                    s.points_of[scan.instances[p]].push_back(scan.T_world_sensor * scan.points[p]);
                }
            }
        }

        std::ifstream in(temp.path / "ground_truth.json");
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

std::vector<Match> MatchWalls(const Simulated& s, const WallResult& result) {
    std::vector<Match> matches;
    for (const TruthWall& t : s.truth) {
        Match m{&t, nullptr, 0};
        for (const Wall& w : result.walls) {
            if (std::abs(w.normal.dot(t.normal)) < std::cos(kMaxMatchAngleDeg * M_PI / 180.0)) {
                continue;
            }
            size_t on = 0;
            for (const auto& c : w.voxels) on += t.Holds(s.map.VoxelCenter(c));
            if (on >= kMinMatchVoxels && on > m.voxels) {
                m.wall = &w;
                m.voxels = on;
            }
        }
        matches.push_back(m);
    }
    return matches;
}

TEST(WallsSimulated, StreetSlantsWithinTheTargets) {
    const Simulated& s = Street();
    const WallResult result = FindWalls(s.map);
    const std::vector<Match> matches = MatchWalls(s, result);

    std::printf(
        "| wall | kind | truth slant | raw points slant | found slant | error | "
        "uncertainty (1 sigma) | inliers | rms m |\n|---|---|---|---|---|---|---|---|---|\n");
    double sum_error = 0.0, max_error = 0.0;
    size_t counted = 0, found = 0;
    for (const Match& m : matches) {
        if (m.truth->length() < kMinTruthLengthM) continue;
        ++counted;
        // What a plane fitted straight to the simulated points of the face gives (the best a
        // map could do with these scans).
        std::vector<Eigen::Vector3d> face;
        const auto raw = s.points_of.find(m.truth->id);
        if (raw != s.points_of.end()) {
            for (const auto& p : raw->second) {
                if (m.truth->Holds(p)) face.push_back(p);
            }
        }
        const double raw_slant = face.size() >= 3 ? SlantDeg(FitPlane(face).plane.normal) : NAN;
        if (!m.wall) {
            std::printf("| %s | %s | %.2f | %.2f | not found | | | | |\n", m.truth->name.c_str(),
                        m.truth->kind.c_str(), m.truth->slant_deg, raw_slant);
            continue;
        }
        ++found;
        const double error = std::abs(m.wall->slant_deg - m.truth->slant_deg);
        sum_error += error;
        max_error = std::max(max_error, error);
        std::printf("| %s | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %zu | %.3f |\n",
                    m.truth->name.c_str(), m.truth->kind.c_str(), m.truth->slant_deg, raw_slant,
                    m.wall->slant_deg, error, m.wall->uncertainty_deg, m.wall->inliers,
                    m.wall->rms_m);
    }
    size_t vegetation = 0, vegetation_as_wall = 0;
    for (const WallPart& p : result.parts) {
        if (p.dominant_class != core::SemanticClass::kVegetation) continue;
        ++vegetation;
        vegetation_as_wall += p.verdict == PartVerdict::kWall;
    }
    const double mean_error = found ? sum_error / found : 0.0;
    const double found_fraction = counted ? static_cast<double>(found) / counted : 0.0;
    const double vegetation_fraction =
        vegetation ? static_cast<double>(vegetation_as_wall) / vegetation : 0.0;
    std::printf(
        "walls found %zu of %zu; mean slant error %.3f deg, max %.3f deg; vegetation "
        "parts taken as walls %zu of %zu; %zu walls reported, %zu parts, %zu candidates\n",
        found, counted, mean_error, max_error, vegetation_as_wall, vegetation, result.walls.size(),
        result.parts.size(), result.stats.candidate_voxels);
    EXPECT_GE(found_fraction, kMinFoundFraction);
    EXPECT_LE(mean_error, kMaxMeanSlantErrorDeg);
    EXPECT_LE(max_error, kMaxSlantErrorDeg);
    EXPECT_GT(vegetation, 0u) << "the street has trees and bushes: the test must see them";
    EXPECT_LE(vegetation_fraction, kMaxVegetationAsWall);
}

}  // namespace
}  // namespace strata::walls
