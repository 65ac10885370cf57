#include "core/geodesy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <cmath>

namespace gins {
namespace GINS_TEST_FILE {

TEST(LocalEnuFrame, RoundTripAndAxes) {
  const LocalEnuFrame frame({31.5, 120.4, 10.0});
  EXPECT_LT(frame.ToEnu({31.5, 120.4, 10.0}).norm(), 1e-9);
  // North of the origin is +y, east is +x, up is +z.
  EXPECT_GT(frame.ToEnu({31.5001, 120.4, 10.0}).y(), 11.0);
  EXPECT_GT(frame.ToEnu({31.5, 120.4001, 10.0}).x(), 9.0);
  EXPECT_NEAR(frame.ToEnu({31.5, 120.4, 15.0}).z(), 5.0, 1e-6);
  const Vec3 p(1234.5, -987.6, 12.3);
  const GeodeticPoint g = frame.ToGeodetic(p);
  EXPECT_LT((frame.ToEnu(g) - p).norm(), 1e-6);
  const LocalEnuFrame copy = frame;
  EXPECT_LT((copy.ToEnu(g) - p).norm(), 1e-6);
}

// The local ENU axes at a point 2 km east of the origin are turned about up by the meridian convergence
// (Δlon·sin(lat), to first order) against the origin's: a direction measured there (a truth file's
// attitude or velocity) must be rotated into w.
TEST(LocalEnuFrame, RotationFromLocalEnu) {
  const LocalEnuFrame frame({31.5, 120.4, 10.0});
  EXPECT_LT((frame.RotationFromLocalEnu({31.5, 120.4, 10.0}) - Mat3::Identity()).norm(), 1e-12);
  const GeodeticPoint east = frame.ToGeodetic(Vec3(2000.0, 0.0, 0.0));
  const Mat3 R_w_l = frame.RotationFromLocalEnu(east);
  EXPECT_LT((R_w_l * R_w_l.transpose() - Mat3::Identity()).norm(), 1e-12);
  EXPECT_NEAR(R_w_l.determinant(), 1.0, 1e-12);
  // Local north, seen in w: yaw 90° plus the convergence (north at the point leans towards the origin's
  // meridian, i.e. counter-clockwise seen from above, east of the origin in the northern hemisphere).
  const Vec3 north_w = R_w_l * Vec3::UnitY();
  const double convergence = (east.lon_deg - 120.4) * kDegToRad * std::sin(31.5 * kDegToRad);
  EXPECT_NEAR(std::atan2(north_w.y(), north_w.x()) - kPi / 2.0, convergence, 1e-2 * convergence);
  // Local up tilts towards +x (away from the origin) by distance / Earth radius.
  const Vec3 up_w = R_w_l * Vec3::UnitZ();
  EXPECT_NEAR(up_w.x(), 2000.0 / 6.38e6, 2e-6);
}

TEST(NormalGravity, KnownValues) {
  EXPECT_NEAR(NormalGravity(0.0, 0.0), 9.7803253, 1e-6);
  EXPECT_NEAR(NormalGravity(90.0, 0.0), 9.8321849, 1e-6);
  EXPECT_LT(NormalGravity(45.0, 1000.0), NormalGravity(45.0, 0.0));
}

TEST(IsPlausibleGeodetic, Ranges) {
  EXPECT_TRUE(IsPlausibleGeodetic(31.5, 120.4, 10.0));
  EXPECT_FALSE(IsPlausibleGeodetic(91.0, 0.0, 0.0));
  EXPECT_FALSE(IsPlausibleGeodetic(0.0, 181.0, 0.0));
  EXPECT_FALSE(IsPlausibleGeodetic(0.0, 0.0, 1e6));
}

// NearGeodetic is ToGeodetic to 1e-10 deg (0.01 mm) and 1e-5 m along a wandering 20 km track of 0.1-2 m
// steps, across the date line and at high latitude, and exact where it renews its reference.
TEST(NearGeodetic, IsToGeodeticToAHundredthOfAMillimetre) {
  for (const GeodeticPoint& origin : {GeodeticPoint{31.5, 120.4, 10.0}, GeodeticPoint{-62.0, 179.99, 300.0}}) {
    const LocalEnuFrame frame(origin);
    NearGeodetic near(frame);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> step(0.1, 2.0), turn(-0.3, 0.3);
    Vec3 p(-1500.0, 800.0, 20.0);
    double heading = 0.0, max_deg = 0.0, max_h = 0.0;
    for (int i = 0; i < 20000; ++i) {
      heading += turn(rng);
      p += step(rng) * Vec3(std::cos(heading), std::sin(heading), 0.01);
      const GeodeticPoint a = near(p), b = frame.ToGeodetic(p);
      double dlon = std::abs(a.lon_deg - b.lon_deg);
      dlon = std::min(dlon, 360.0 - dlon);
      max_deg = std::max({max_deg, std::abs(a.lat_deg - b.lat_deg), dlon});
      max_h = std::max(max_h, std::abs(a.alt_m - b.alt_m));
      ASSERT_LE(std::abs(a.lon_deg), 180.0);
    }
    EXPECT_LT(max_deg, 1e-10) << origin.lat_deg;
    EXPECT_LT(max_h, 1e-5) << origin.lat_deg;
    EXPECT_GT(max_deg, 0.0);  // the first order is not exact: the test does see the approximation
  }
}

}  // namespace
}  // namespace gins
