// The matching surface read from a stored map around the source only (registration::MapSurface,
// the map's tiles read by threads: the ThreadSanitizer step runs this file), on two rooms stored
// in many tiles (docs/registration.md).
#include <gtest/gtest.h>

#include "Sanitizer.hpp"
#include "StoreTestUtil.hpp"
#include "strata/registration/MapRegion.hpp"
#include "strata/registration/MapSurface.hpp"
#include "strata/registration/Register.hpp"
#include "strata/registration/Surface.hpp"

namespace strata::registration {
namespace {

// The alignment against the surface read around the source is the one against the surface of
// every point of the box, bit for bit; also when any move of a point to another cell reads the
// level again. A scan like the first room's, and a guess 0.3 m and 3 deg off: where it lands is
// not the point here (TestRegister.cpp holds the accuracy).
TEST(MapSurface, TheSurfaceReadAroundTheSourceAlignsAsTheWholeBoxsSurface) {
    store::MapStore map = store::test::NewMapOfManyTiles(store::test::Temp("map_surface"));
    (void)store::test::Write(map, store::test::Session(1, {0.4, 0.2, 0.0}, 3));
    (void)store::test::Write(map, store::test::Session(9, {3.1, -1.7, 0.3}, 2));
    const std::vector<Eigen::Vector3d> source = store::test::RoomScan(77, {0.4, 0.5, 0.1}).points;
    const Eigen::Isometry3d guess = PoseFromXyzYaw(0.7, 0.4, 0.1, 3.0);
    RegistrationConfig config;
    config.min_source_range_m = 0.5;
    config.max_source_range_m = 60.0;
    const Eigen::AlignedBox3d near = BoundsOf(source, guess, /*margin_m=*/10.0);
    const RegistrationResult w = RegisterPoints(
        Surface::FromPoints(OccupiedPoints(map.LoadMap(map.Latest()), near), config.surface),
        source, guess, config);
    EXPECT_GT(w.iterations, 1);
    MapSurface around(map, map.Latest(), near, config.surface);
    const RegistrationResult a = RegisterPoints(around, source, guess, config);
    EXPECT_TRUE(a.T_map_source.matrix() == w.T_map_source.matrix());
    EXPECT_EQ(a.iterations, w.iterations);
    EXPECT_GE(around.reads(), config.surface.level_cells_m.size());
    // With no cover, every move reads again: the same calls, 70 of this test's 95 s under TSan
    // (run for the threads of a pass), so only the normal build makes them.
    if (strata::testing::UnderSanitizer()) return;
    MapSurface tight(map, map.Latest(), near, config.surface, /*cover_cells=*/0);
    const RegistrationResult t = RegisterPoints(tight, source, guess, config);
    EXPECT_TRUE(t.T_map_source.matrix() == w.T_map_source.matrix());
    EXPECT_GT(tight.reads(), around.reads());
}

}  // namespace
}  // namespace strata::registration
