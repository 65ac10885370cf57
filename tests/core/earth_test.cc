#include "core/earth.h"

#include <gtest/gtest.h>

#include <GeographicLib/NormalGravity.hpp>
#include <cmath>

namespace gins {
namespace GINS_TEST_FILE {

const LocalEnuFrame kFrame(GeodeticPoint{31.5, 120.4, 10.0});

TEST(EarthModelTest, EarthRateInTheTangentFrame) {
  const EarthModel e = EarthModel::Rotating(kFrame);
  EXPECT_TRUE(e.rotating());
  EXPECT_NEAR(e.rate_w().norm(), kEarthRate, 1e-18);
  EXPECT_EQ(e.rate_w().x(), 0.0);  // no east component
  EXPECT_NEAR(std::atan2(e.rate_w().z(), e.rate_w().y()), 31.5 * kDegToRad, 1e-12);  // up at the latitude
  const EarthModel flat(9.8);
  EXPECT_FALSE(flat.rotating());
  EXPECT_EQ(flat.rate_w(), Vec3::Zero());
  EXPECT_EQ(flat.Gravity(Vec3(5e4, 0, 0)), Vec3(0, 0, -9.8));
}

TEST(EarthModelTest, GravityAtTheOriginIsNormalGravityDown) {
  const EarthModel e = EarthModel::Rotating(kFrame);
  const Vec3 g = e.Gravity(Vec3::Zero());
  EXPECT_NEAR(g.norm(), NormalGravity(31.5, 10.0), 1e-9);
  EXPECT_NEAR(g.x(), 0.0, 1e-12);
  EXPECT_LT(std::abs(g.y()), 1e-6);  // normal gravity is normal to the ellipsoid: ~no north component
  EXPECT_NEAR(e.g_norm(), g.norm(), 1e-15);
}

TEST(EarthModelTest, GravityFollowsTheLocalVertical) {
  const EarthModel e = EarthModel::Rotating(kFrame);
  // 10 km east the plumb line leans toward the origin's vertical by ~distance / radius.
  const Vec3 g = e.Gravity(Vec3(1e4, 0, 0));
  const double lean = std::atan2(-g.x(), -g.z());
  EXPECT_NEAR(lean, 1e4 / 6.38e6, 2e-5);
  EXPECT_GT(lean, 0.0);
  // The cached linearisation agrees with the exact value everywhere along a drive, refreshes included.
  for (double d : {0.0, 150.0, 499.0, 700.0, 9000.0, 30000.0, 29000.0, 100.0}) {
    const Vec3 p(d, -0.4 * d, 0.01 * d);
    EXPECT_LT((e.Gravity(p) - NormalGravityWorld(kFrame, p)).norm(), 2e-7) << d;
  }
  // Height: the free-air gradient, about −3.1e-6 /s² per metre.
  EXPECT_NEAR(e.Gravity(Vec3(0, 0, 100)).norm() - e.Gravity(Vec3::Zero()).norm(), -3.1e-4, 1e-5);
}

// The same Earth backwards: its rotation negated, its gravity as it was.
TEST(EarthModelTimeReversed, NegatesTheRotationAlone) {
  const EarthModel e = EarthModel::Rotating(LocalEnuFrame({40.0, -105.0, 1600.0}));
  const EarthModel r = e.TimeReversed();
  EXPECT_EQ(r.rate_w(), -e.rate_w());
  EXPECT_GT(e.rate_w().norm(), 7e-5);
  const Vec3 p(1200.0, -300.0, 15.0);
  EXPECT_EQ(r.Gravity(p), e.Gravity(p));
  EXPECT_EQ(r.g_norm(), e.g_norm());
}

}  // namespace
}  // namespace gins
