#include <gtest/gtest.h>

#include <random>

#include "MapDiff.hpp"
#include "strata/core/Error.hpp"
#include "strata/integration/UpdateParts.hpp"

namespace strata::integration {
namespace {

// Labelled points on the walls of a 9 x 7 x 3 m room seen from inside, 0.1 m voxels: rays
// cross many leaves, endpoints fall in many voxels of several classes.
core::Scan LabelledRoom(uint32_t seed, size_t n = 4000) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    core::Scan scan;
    scan.T_world_sensor.translation() = Eigen::Vector3d(0.33, -0.21, 0.07);
    for (size_t i = 0; i < n; ++i) {
        Eigen::Vector3d d;  // one draw per statement: the scan must not depend on the compiler
        d.x() = u(rng);
        d.y() = u(rng);
        d.z() = u(rng);
        const double t = (Eigen::Array3d(4.5, 3.5, 1.5) / d.array().abs()).minCoeff();
        scan.points.push_back(d * t);
        scan.labels.push_back(d.z() < -0.9 ? core::SemanticClass::kGround
                                           : core::SemanticClass::kBuilding);
    }
    return scan;
}

bool EvenLeafColumn(const openvdb::Coord& leaf) { return (leaf.x() >> 3) % 2 == 0; }

TEST(UpdateParts, PartsOfAPartitionApplyToTheWholeUpdate) {
    const IntegrationConfig config;
    core::VoxelMap whole = core::VoxelMap::Create(0.1);
    core::VoxelMap parts = core::VoxelMap::Create(0.1);
    for (uint32_t seed = 1; seed <= 3; ++seed) {
        const ScanUpdate update = ComputeScanUpdate(LabelledRoom(seed), whole, config);
        const ScanUpdate even = SelectUpdate(update, EvenLeafColumn);
        const ScanUpdate odd =
            SelectUpdate(update, [](const openvdb::Coord& leaf) { return !EvenLeafColumn(leaf); });
        EXPECT_GT(even.free->leafCount(), 0u);
        EXPECT_GT(odd.free->leafCount(), 0u);
        EXPECT_EQ(even.free->leafCount() + odd.free->leafCount(), update.free->leafCount());
        EXPECT_EQ(even.endpoints.size() + odd.endpoints.size(), update.endpoints.size());
        EXPECT_EQ(even.points, update.points);
        ApplyScanUpdate(update, whole, config);
        ApplyScanUpdate(odd, parts, config);
        ApplyScanUpdate(even, parts, config);
    }
    EXPECT_EQ(testing::MapDifference(whole, parts), "");
}

TEST(UpdateParts, EncodedUpdatesDecodeToTheSameUpdate) {
    IntegrationConfig config;
    config.crossed_margin_m = 0.5;  // a session writer's updates carry the crossed space
    core::VoxelMap map = core::VoxelMap::Create(0.1);
    const ScanUpdate update = ComputeScanUpdate(LabelledRoom(5), map, config);
    const ScanUpdate back = DecodeUpdate(EncodeUpdate(update), "rank 1");
    ASSERT_TRUE(update.crossed && back.crossed);
    EXPECT_TRUE(back.crossed->hasSameTopology(*update.crossed));
    EXPECT_FALSE(
        DecodeUpdate(EncodeUpdate(ComputeScanUpdate(LabelledRoom(5), map, {})), "rank 1").crossed);
    EXPECT_EQ(back.points, update.points);
    EXPECT_EQ(back.dropped, update.dropped);
    EXPECT_EQ(back.clipped, update.clipped);
    EXPECT_TRUE(back.free->hasSameTopology(*update.free));
    EXPECT_TRUE(back.occupied->hasSameTopology(*update.occupied));
    ASSERT_EQ(back.endpoints.size(), update.endpoints.size());
    for (size_t i = 0; i < back.endpoints.size(); ++i) {
        EXPECT_EQ(back.endpoints[i].ijk, update.endpoints[i].ijk);
        EXPECT_EQ(back.endpoints[i].points, update.endpoints[i].points);
        EXPECT_EQ(back.endpoints[i].label, update.endpoints[i].label);
        EXPECT_EQ(back.endpoints[i].offset_sum, update.endpoints[i].offset_sum);  // bit for bit
    }
}

// A part is encoded without building its trees: the bytes are those of the selected part's.
TEST(UpdateParts, EncodingAPartGivesTheBytesOfTheSelectedPart) {
    core::VoxelMap map = core::VoxelMap::Create(0.1);
    const ScanUpdate update = ComputeScanUpdate(LabelledRoom(7), map, {});
    const LeafFilter odd = [](const openvdb::Coord& leaf) { return !EvenLeafColumn(leaf); };
    for (const LeafFilter& keep : {LeafFilter(EvenLeafColumn), odd}) {
        const std::string part = EncodeUpdate(update, keep);
        EXPECT_EQ(part, EncodeUpdate(SelectUpdate(update, keep)));
        EXPECT_LT(part.size(), EncodeUpdate(update).size());
    }
    EXPECT_EQ(EncodeUpdate(update, [](const openvdb::Coord&) { return true; }),
              EncodeUpdate(update));
}

TEST(UpdateParts, DamagedBytesAreRefusedNamingTheSender) {
    core::VoxelMap map = core::VoxelMap::Create(0.1);
    const std::string bytes = EncodeUpdate(ComputeScanUpdate(LabelledRoom(6, 500), map, {}));
    const auto refused = [](const std::string& b, const char* problem) {
        try {
            (void)DecodeUpdate(b, "rank 2");
        } catch (const FormatError& e) {
            const std::string what = e.what();
            return what.find("rank 2") != std::string::npos &&
                   what.find(problem) != std::string::npos;
        }
        return false;
    };
    EXPECT_TRUE(refused(bytes.substr(0, bytes.size() - 3), "truncated"));
    EXPECT_TRUE(refused(bytes + "x", "trailing"));
    EXPECT_TRUE(refused("", "truncated"));
    std::string version = bytes;
    version[0] ^= 1;
    EXPECT_TRUE(refused(version, "version"));
    std::string origin = bytes;
    origin[4 + 3 * 8 + 8] ^= 1;  // the first free leaf's x origin, no longer a multiple of 8
    EXPECT_TRUE(refused(origin, "multiple of 8"));
}

}  // namespace
}  // namespace strata::integration
