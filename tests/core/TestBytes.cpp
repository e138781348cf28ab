// What ranks send each other: a record named once by core::Fields comes back field for field,
// and bytes cut short are refused rather than read past their end.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "strata/core/Bytes.hpp"
#include "strata/core/GridTypes.hpp"

namespace strata::core::test {

// A record like the walls' and vehicles': Eigen vectors, a plain key, a vector of records.
struct Inner {
    Eigen::Vector2d xy = Eigen::Vector2d::Zero();
    std::vector<openvdb::Coord> voxels;
};
struct Outer {
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    double d = 0.0;
    std::vector<std::pair<int, Inner>> parts;
};

}  // namespace strata::core::test

namespace strata::core {

template <>
struct Fields<test::Inner> {
    template <typename Io, typename R>
    static void Visit(Io& io, R& r) {
        io(r.xy, r.voxels);
    }
};

template <>
struct Fields<test::Outer> {
    template <typename Io, typename R>
    static void Visit(Io& io, R& r) {
        io(r.normal, r.d, r.parts);
    }
};

}  // namespace strata::core

namespace strata::core::test {
namespace {

Outer Example() {
    Outer o;
    o.normal = {0.6, -0.8, std::numeric_limits<double>::denorm_min()};
    o.d = -1.0 / 3.0;
    Inner a;
    a.xy = {1e300, -0.0};
    a.voxels = {openvdb::Coord(1, -2, 3), openvdb::Coord(-4, 5, -6)};
    o.parts = {{7, a}, {-1, Inner{}}};
    return o;
}

TEST(Bytes, ARecordComesBackFieldForFieldBitForBit) {
    const Outer sent = Example();
    std::string bytes;
    Put(bytes, sent);
    Put(bytes, uint64_t{42});
    ByteReader in(bytes, "test");
    const auto got = in.Get<Outer>();
    EXPECT_EQ(in.Get<uint64_t>(), 42u);
    EXPECT_TRUE(in.Rest().empty());
    EXPECT_EQ(got.normal, sent.normal);
    EXPECT_EQ(std::memcmp(&got.d, &sent.d, sizeof(double)), 0);
    ASSERT_EQ(got.parts.size(), 2u);
    EXPECT_EQ(got.parts[0].first, 7);
    EXPECT_EQ(got.parts[0].second.xy, sent.parts[0].second.xy);
    EXPECT_TRUE(std::signbit(got.parts[0].second.xy.y()));
    EXPECT_EQ(got.parts[0].second.voxels, sent.parts[0].second.voxels);
    EXPECT_EQ(got.parts[1].first, -1);
    EXPECT_TRUE(got.parts[1].second.voxels.empty());
}

TEST(Bytes, BytesCutShortAreRefusedAtEveryLength) {
    std::string bytes;
    Put(bytes, Example());
    for (size_t n = 0; n < bytes.size(); ++n) {
        const std::string cut = bytes.substr(0, n);
        ByteReader in(cut, "test");
        EXPECT_THROW((void)in.Get<Outer>(), FormatError) << n;
    }
}

}  // namespace
}  // namespace strata::core::test
