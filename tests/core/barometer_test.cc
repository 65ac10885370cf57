// The barometer module (core/barometer.h): its record's numbers both ways and their range checks, its height
// model against GeographicLib's exact conversion of w, and its measurement from a record.
#include "core/barometer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace gins {
namespace GINS_TEST_FILE {

using Baro = BarometerModule;

TEST(Barometer, RecordNumbersBothWays) {
  for (const size_t n : {size_t{2}, size_t{3}}) {
    const double v[] = {1700000000.25, 123.456, 0.75};
    Baro::Record r;
    Baro::Record::Fill(v, n, &r);
    EXPECT_EQ(r.t, v[0]);
    EXPECT_EQ(r.alt_m, v[1]);
    EXPECT_EQ(r.sigma_m, n == 3 ? v[2] : 0.0);
    double back[3] = {};
    ASSERT_EQ(Baro::Record::Values(r, back), n);
    for (size_t i = 0; i < n; ++i) EXPECT_EQ(back[i], v[i]);
  }
}

TEST(Barometer, AbsurdValuesAreNamed) {
  const double good[] = {1.0, 12.0, 0.5};
  EXPECT_EQ(Baro::Record::Absurd(good, 3), "");
  EXPECT_EQ(Baro::Record::Absurd(good, 2), "");
  const double high[] = {1.0, 2e5};
  EXPECT_NE(Baro::Record::Absurd(high, 2).find("(alt)"), std::string::npos);
  const double low[] = {1.0, -1000.0};
  EXPECT_NE(Baro::Record::Absurd(low, 2).find("(alt)"), std::string::npos);
  for (const double sigma : {0.0, -1.0, 1e4}) {
    const double v[] = {1.0, 12.0, sigma};
    EXPECT_NE(Baro::Record::Absurd(v, 3).find("(sigma)"), std::string::npos) << sigma;
  }
}

// The model's height of a point of w against the exact one, out to 20 km from the origin and 3 km up: the
// second-order curvature leaves millimetres where the tangent plane alone is off by metres.
TEST(Barometer, HeightModelMatchesTheEllipsoid) {
  for (const double lat : {0.0, 31.5, 60.0, -45.0}) {
    const LocalEnuFrame w(GeodeticPoint{lat, 120.4, 35.0});
    Baro::Record r;
    r.alt_m = w.origin().alt_m;
    const Baro::Measurement m = *Baro::ToMeasurement(r, Baro::Options{}, w);
    EXPECT_EQ(m.height, 0.0);
    double worst = 0.0, plane = 0.0;
    for (const double d : {1e3, 5e3, 1e4, 2e4}) {
      for (int k = 0; k < 8; ++k) {
        const double a = k * kPi / 4.0 + 0.3;
        for (const double up : {-20.0, 0.0, 3000.0}) {
          const Vec3 p(d * std::cos(a), d * std::sin(a), up);
          Baro::Model model{m};
          model.m.sigma = 1.0;
          double residual = 0.0;
          model(PredictedKinematics<double>{p, Vec3::Zero(), Quat::Identity()}, &residual);
          const double exact = w.ToGeodetic(p).alt_m - w.origin().alt_m;
          worst = std::max(worst, std::abs(residual - exact) / (d <= 1e4 ? 1.0 : 8.0));
          plane = std::max(plane, std::abs(p.z() - exact));
        }
      }
    }
    EXPECT_LT(worst, 5e-3) << "lat " << lat;  // within 10 km (8 times that at 20 km)
    EXPECT_GT(plane, 30.0) << "lat " << lat;  // what the plane alone misses at 20 km
  }
}

TEST(Barometer, MeasurementFromARecord) {
  const LocalEnuFrame w(GeodeticPoint{31.5, 120.4, 10.0});
  Baro::Options o;
  Baro::Record r{5.0, 22.5, 0.0};
  Baro::Measurement m = *Baro::ToMeasurement(r, o, w);
  EXPECT_EQ(m.t, 5.0);
  EXPECT_DOUBLE_EQ(m.height, 12.5);
  EXPECT_EQ(m.sigma, o.sigma);  // none logged: the config's
  r.sigma_m = 0.01;
  EXPECT_EQ(Baro::ToMeasurement(r, o, w)->sigma, o.min_sigma);  // raised to the floor
  r.sigma_m = 2.0;
  EXPECT_EQ(Baro::ToMeasurement(r, o, w)->sigma, 2.0);
  o.enabled = false;
  EXPECT_FALSE(Baro::ToMeasurement(r, o, w).has_value());
}

}  // namespace GINS_TEST_FILE
}  // namespace gins
