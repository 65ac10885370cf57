// Line of sight, troposphere, ionosphere and σ model (core/gnss_atmosphere.h).
#include <gtest/gtest.h>

#include <cmath>

#include "core/gnss_atmosphere.h"

namespace gins {
namespace GINS_TEST_FILE {

TEST(GnssAtmosphere, AzimuthElevationOfKnownDirections) {
  // On the equator at longitude 0, the local ENU axes are ECEF (y, z, x).
  const Vec3 rx(6378137.0, 0.0, 0.0);
  AzEl a = SatelliteAzEl(rx, rx + Vec3(1e7, 0, 0));
  EXPECT_NEAR(a.el, kPi / 2.0, 1e-12);
  a = SatelliteAzEl(rx, rx + Vec3(0, 0, 1e7));  // north on the horizon
  EXPECT_NEAR(a.el, 0.0, 1e-12);
  EXPECT_NEAR(a.az, 0.0, 1e-12);
  a = SatelliteAzEl(rx, rx + Vec3(1e7, 1e7, 0));  // east, 45° up
  EXPECT_NEAR(a.el, kPi / 4.0, 1e-12);
  EXPECT_NEAR(a.az, kPi / 2.0, 1e-12);
  a = SatelliteAzEl(rx, rx + Vec3(0, -1e7, 0));  // west
  EXPECT_NEAR(a.az, 1.5 * kPi, 1e-12);
}

TEST(GnssAtmosphere, SaastamoinenZenithDelayAtSeaLevel) {
  const Atmosphere atm = StandardAtmosphere(0.0, 0.0);
  EXPECT_DOUBLE_EQ(atm.pressure_hpa, 1013.25);
  EXPECT_NEAR(atm.temperature_k, 288.16, 1e-12);
  EXPECT_DOUBLE_EQ(atm.water_vapour_hpa, 0.0);
  // The published hydrostatic zenith delay at 1013.25 hPa, 45°, sea level: 0.0022768 × 1013.25 = 2.3070 m
  // (Saastamoinen 1972; Davis et al. 1985: "about 2.3 m").
  const ZenithDelay z = SaastamoinenZenith(atm, 45.0 * kDegToRad, 0.0);
  EXPECT_NEAR(z.hydrostatic_m, 2.3070, 1e-4);
  EXPECT_DOUBLE_EQ(z.wet_m, 0.0);
  // 70 % humidity at 15 °C: e ≈ 11.9 hPa, wet delay ≈ 0.002277·(1255/288.16 + 0.05)·e ≈ 0.12 m.
  const Atmosphere humid = StandardAtmosphere(0.0, 0.7);
  EXPECT_NEAR(humid.water_vapour_hpa, 11.9, 0.2);
  EXPECT_NEAR(SaastamoinenZenith(humid, 45.0 * kDegToRad, 0.0).wet_m, 0.12, 0.01);
  // Slant: 1/sin(el); none below the horizon or out of the troposphere model's heights.
  const double zenith = SaastamoinenSlant(0.7, 1600.0, kPi / 2.0);
  EXPECT_NEAR(SaastamoinenSlant(0.7, 1600.0, 30.0 * kDegToRad), 2.0 * zenith, 1e-12);
  EXPECT_NEAR(zenith, 1.93, 0.05);  // 1600 m (Colorado): ≈ 840 hPa
  EXPECT_EQ(SaastamoinenSlant(0.7, 1600.0, -0.1), 0.0);
  EXPECT_EQ(SaastamoinenSlant(0.7, 2e4, 0.5), 0.0);
}

// RTKLIB's fallback parameters (rtkcmn.c ion_default, 2004/1/1), used when a file gives none.
const std::array<double, 4> kAlpha = {0.1118E-07, -0.7451E-08, -0.5961E-07, 0.1192E-06};
const std::array<double, 4> kBeta = {0.1167E+06, -0.2294E+06, -0.1311E+06, 0.1049E+07};

TEST(GnssAtmosphere, KlobucharMatchesAnIndependentEvaluation) {
  // Expected values from an independent Python transcription of IS-GPS-200 figure 20-4 (semicircles, the
  // polynomials summed term by term, ψ/φi/λi/φm/t/F/AMP/PER/x as the figure names them):
  //   klob(lat_deg, lon_deg, az_deg, el_deg, gps_sow) → 3.210199, 5.153927, 2.025446 m.
  auto k = [](double lat, double lon, double az, double el, double t) {
    return KlobucharL1Delay(kAlpha, kBeta, lat * kDegToRad, lon * kDegToRad, az * kDegToRad, el * kDegToRad, t);
  };
  EXPECT_NEAR(k(39.7, -105.0, 64.1, 50.6, 408639.748), 3.210199, 1e-6);
  EXPECT_NEAR(k(40.0, -105.0, 210.0, 20.0, 408640.0), 5.153927, 1e-6);
  EXPECT_NEAR(k(40.0, 100.0, 0.0, 45.0, 0.0), 2.025446, 1e-6);  // night: the constant 5 ns × F
  EXPECT_EQ(k(40.0, 100.0, 0.0, -1.0, 0.0), 0.0);
}

TEST(GnssAtmosphere, IonosphereFreeCombinationRemovesAnInverseSquareDelay) {
  const double f1 = 1575.42e6, f5 = 1176.45e6, rho = 2.2e7, i1 = 4.0;
  const double p1 = rho + i1, p5 = rho + i1 * (f1 / f5) * (f1 / f5);
  EXPECT_NEAR(IonosphereFreeCombination(p1, f1, p5, f5), rho, 1e-6);
}

TEST(GnssAtmosphere, SigmaModel) {
  PseudorangeSigmaModel m;
  EXPECT_NEAR(m.Sigma(kPi / 2.0, 45.0), std::sqrt(0.18), 1e-12);
  EXPECT_NEAR(m.Sigma(30.0 * kDegToRad, 45.0), std::sqrt(0.09 + 0.36), 1e-12);
  m.c_m = 0.5;
  EXPECT_NEAR(m.Sigma(kPi / 2.0, 35.0), std::sqrt(0.18 + 0.25 * 10.0), 1e-12);  // 10 dB below: ×10 in variance
  EXPECT_NEAR(m.Sigma(kPi / 2.0, 50.0), std::sqrt(0.18 + 0.25), 1e-12);
}

}  // namespace
}  // namespace gins
