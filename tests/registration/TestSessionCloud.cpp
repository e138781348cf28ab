// The session cloud a session is aligned with (registration/SessionCloud.hpp): the first point of
// each cell, in the order they came, and past `max_points` cells a sample of them that does not
// depend on the order of the scans.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "SyntheticGeometry.hpp"
#include "strata/registration/SessionCloud.hpp"

namespace strata::registration::session_cloud_tests {
namespace {

using Cell = std::tuple<int, int, int>;
using test::Street;

Cell CellOf(const Eigen::Vector3d& p, double cell_m) {
    return {int(std::floor(p.x() / cell_m)), int(std::floor(p.y() / cell_m)),
            int(std::floor(p.z() / cell_m))};
}

// Scans of the synthetic street from a few poses along it, in the street's frame.
std::vector<core::Scan> Scans() {
    std::vector<core::Scan> scans;
    for (unsigned k = 0; k < 6; ++k) {
        core::Scan scan;
        scan.T_world_sensor = Eigen::Isometry3d::Identity();
        scan.T_world_sensor.translation() = Eigen::Vector3d(2.0 * k, 0.5, 1.5);
        for (const Eigen::Vector3d& p : Street(k + 1, 0.07)) {
            scan.points.push_back(scan.T_world_sensor.inverse() * p);
        }
        scans.push_back(std::move(scan));
    }
    return scans;
}

// The cloud by its definition: each cell's first point in range, in the order they came.
std::vector<Eigen::Vector3d> FirstPerCell(const std::vector<core::Scan>& scans,
                                          const SessionCloudConfig& config) {
    std::set<Cell> seen;
    std::vector<Eigen::Vector3d> out;
    for (const core::Scan& scan : scans) {
        for (const Eigen::Vector3d& q : scan.points) {
            const double r = q.norm();
            if (r < config.min_range_m || r > config.max_range_m) continue;
            const Eigen::Vector3d p = scan.T_world_sensor * q;
            if (seen.insert(CellOf(p, config.cell_m)).second) out.push_back(p);
        }
    }
    return out;
}

TEST(SessionCloud, KeepsEachCellsFirstPointInTheOrderTheyCame) {
    SessionCloudConfig config;
    config.min_range_m = 0.5;
    const std::vector<core::Scan> scans = Scans();
    const std::vector<Eigen::Vector3d> expected = FirstPerCell(scans, config);
    ASSERT_GT(expected.size(), 10000u);
    ASSERT_LT(expected.size(), config.max_points);
    EXPECT_TRUE(SessionCloud(scans, config) == expected);
}

TEST(SessionCloud, PastItsLimitKeepsTheSameCellsWhateverTheOrderOfTheScans) {
    SessionCloudConfig config;
    config.min_range_m = 0.5;
    std::vector<core::Scan> scans = Scans();
    const std::vector<Eigen::Vector3d> all = FirstPerCell(scans, config);
    config.max_points = all.size() / 4;
    const std::vector<Eigen::Vector3d> sample = SessionCloud(scans, config);
    ASSERT_LE(sample.size(), config.max_points);
    ASSERT_GT(sample.size(), config.max_points / 2);
    // Each a cell's first point, in the order they came: a subsequence of the whole cloud.
    auto next = all.begin();
    for (const Eigen::Vector3d& p : sample) {
        next = std::find(next, all.end(), p);
        ASSERT_NE(next, all.end()) << "not the first point of its cell, or out of order";
    }
    // Spread over the street, not its first scans: a quarter of the cells of each half.
    const auto west = [](const Eigen::Vector3d& p) { return p.x() < 5.0; };
    const double west_all = double(std::count_if(all.begin(), all.end(), west)) / all.size();
    const double west_sample =
        double(std::count_if(sample.begin(), sample.end(), west)) / sample.size();
    EXPECT_NEAR(west_sample, west_all, 0.03);
    // The same cells with the scans in reverse.
    std::reverse(scans.begin(), scans.end());
    std::set<Cell> a, b;
    for (const Eigen::Vector3d& p : sample) a.insert(CellOf(p, config.cell_m));
    for (const Eigen::Vector3d& p : SessionCloud(scans, config)) b.insert(CellOf(p, config.cell_m));
    EXPECT_TRUE(a == b);
}

}  // namespace
}  // namespace strata::registration::session_cloud_tests
