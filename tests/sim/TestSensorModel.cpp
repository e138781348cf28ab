#include <gtest/gtest.h>

#include <stdexcept>

#include "strata/sim/SensorModel.hpp"

namespace strata::sim {

TEST(SensorModel, Hdl64SpansTheDatasheetFieldOfView) {
    const SensorModel s = SensorModel::FromName("hdl64");
    ASSERT_EQ(s.beams(), 64U);
    EXPECT_NEAR(s.elevation_deg.front(), 2.0, 1e-9);
    EXPECT_NEAR(s.elevation_deg.back(), -24.8, 1e-9);
    EXPECT_NEAR(s.azimuth_resolution_deg(), 0.1728, 1e-3);
    EXPECT_DOUBLE_EQ(s.rate_hz, 10.0);
}

}  // namespace strata::sim
