#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "strata/core/Error.hpp"
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

namespace strata::sim {

TEST(SensorModel, Vlp16AndOusterTablesAreUniform) {
    const SensorModel vlp = SensorModel::FromName("vlp16");
    ASSERT_EQ(vlp.beams(), 16U);
    for (size_t b = 0; b < vlp.beams(); ++b)
        EXPECT_NEAR(vlp.elevation_deg[b], 15.0 - 2.0 * b, 1e-12);
    EXPECT_NEAR(vlp.azimuth_resolution_deg(), 0.2, 1e-12);
    for (int beams : {64, 128}) {
        const SensorModel os1 = SensorModel::FromName("os1-" + std::to_string(beams));
        ASSERT_EQ(os1.beams(), static_cast<size_t>(beams));
        EXPECT_NEAR(os1.elevation_deg.front(), 22.5, 1e-12);
        EXPECT_NEAR(os1.elevation_deg.back(), -22.5, 1e-12);
        EXPECT_NEAR(os1.elevation_deg[0] - os1.elevation_deg[1], 45.0 / (beams - 1), 1e-12);
    }
}

TEST(SensorModel, ColumnsSweepOnceClockwiseFromBehind) {
    const SensorModel s = SensorModel::FromName("hdl64");
    EXPECT_NEAR(s.ColumnAzimuthRad(0), M_PI - M_PI / s.columns, 1e-12);
    EXPECT_NEAR(s.ColumnTimeS(s.columns - 1), 0.1 - 0.05 / s.columns, 1e-12);
    EXPECT_GT(s.ColumnAzimuthRad(0), s.ColumnAzimuthRad(1));  // clockwise seen from above
}

TEST(SensorModel, RejectsUnknownNamesAndNonsense) {
    EXPECT_THROW((void)SensorModel::FromName("hdl32"), InvalidArgumentError);
    SensorModel s = SensorModel::FromName("vlp16");
    s.max_range_m = 0.1;
    EXPECT_THROW(s.Validate(), InvalidArgumentError);
    s = SensorModel::FromName("vlp16");
    s.dropout_probability = 1.0;
    EXPECT_THROW(s.Validate(), InvalidArgumentError);
    s = SensorModel::FromName("vlp16");
    s.elevation_deg.clear();
    EXPECT_THROW(s.Validate(), InvalidArgumentError);
}

}  // namespace strata::sim
