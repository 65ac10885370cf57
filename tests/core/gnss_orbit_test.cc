// Broadcast-ephemeris satellite models (core/gnss_orbit.h): position against a published worked example,
// velocity against the position's central difference (MEO, IGSO, GEO), the relativistic term against its
// closed form, BeiDou GEO's rotation, week wrap, group delays and ephemeris selection.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/gnss_orbit.h"
#include "core/io/rinex.h"

namespace gins {
namespace GINS_TEST_FILE {

// The GPS ephemeris of szymon2024/gps-labs, gps_lab02 (an independent Haskell transcription of IS-GPS-200
// Table 20-IV), whose printed result at week 2304, 424830 s is X = 22151566.575334515,
// Y = 13275548.286060918, Z = 7260529.645377433 m.
KeplerEphemeris WorkedExample() {
  KeplerEphemeris e;
  e.sat = {GnssSystem::kGps, 1};
  e.crs_m = 134.75;
  e.delta_n_rad_s = 4.12374319903e-9;
  e.m0_rad = -2.23037324521;
  e.cuc_rad = 7.25500285625e-6;
  e.e = 1.61300709005e-2;
  e.cus_rad = 8.00378620625e-6;
  e.sqrt_a_sqrt_m = 5153.71900558;
  e.toe_s = 424800.0;
  e.cic_rad = 7.07805156708e-8;
  e.omega0_rad = -2.84371723002;
  e.cis_rad = 2.6635825634e-7;
  e.i0_rad = 0.967821256634;
  e.crc_m = 226.75;
  e.omega_rad = -1.2251476939;
  e.omega_dot_rad_s = -7.73246494535e-9;
  e.idot_rad_s = 2.60367988229e-10;
  e.week = 2304;
  e.toc_gps_s = e.toe_gps_s();
  return e;
}

RinexNav BundledNav() {
  return ReadRinexNav(std::string(GINS_TEST_DATA_DIR) + "/rinex/walk.nav", InputOptions{});
}

TEST(GnssOrbit, PositionMatchesThePublishedWorkedExample) {
  const KeplerEphemeris e = WorkedExample();
  const SatelliteState s = KeplerSatelliteState(e, 2304 * kSecondsPerWeek + 424830.0);
  // Both solve Kepler's equation to ≤ 1e-12 rad (≤ 30 µm): 1 mm.
  EXPECT_NEAR(s.position_ecef_m.x(), 22151566.575334515, 1e-3);
  EXPECT_NEAR(s.position_ecef_m.y(), 13275548.286060918, 1e-3);
  EXPECT_NEAR(s.position_ecef_m.z(), 7260529.645377433, 1e-3);
}

TEST(GnssOrbit, WeekRolloverWrapsTheTimeFromToe) {
  EXPECT_DOUBLE_EQ(WrapHalfWeek(302400.0), 302400.0);
  EXPECT_DOUBLE_EQ(WrapHalfWeek(302401.0), 302401.0 - kSecondsPerWeek);
  EXPECT_DOUBLE_EQ(WrapHalfWeek(-302401.0), -302401.0 + kSecondsPerWeek);
  EXPECT_DOUBLE_EQ(WrapHalfWeek(-100.0), -100.0);
  // An ephemeris of the week's end used just after the rollover, with its week number one less: the same
  // state as with the continuous time.
  KeplerEphemeris e = WorkedExample();
  e.toe_s = 604000.0;
  e.toc_gps_s = e.toe_gps_s();
  const double t = 2305 * kSecondsPerWeek + 100.0;  // 900 s after toe
  const SatelliteState a = KeplerSatelliteState(e, t);
  const SatelliteState b = KeplerSatelliteState(e, t - 2.0 * kSecondsPerWeek);  // t − toe wraps to +900 s
  EXPECT_LT((a.position_ecef_m - b.position_ecef_m).norm(), 1e-6);
}

// d/dt of the position by a central difference of ±0.5 s: truncation |a'''|·h²/6 < 1e-6 m/s for an orbit.
Vec3 NumericVelocity(const KeplerEphemeris& e, double t) {
  const double h = 0.5;
  return (KeplerSatelliteState(e, t + h).position_ecef_m - KeplerSatelliteState(e, t - h).position_ecef_m) / (2 * h);
}

TEST(GnssOrbit, VelocityAndClockDriftAreTheDerivativesOfPositionAndClock) {
  const RinexNav nav = BundledNav();
  int checked = 0;
  for (const KeplerEphemeris& e : nav.kepler) {
    const double t = e.toe_gps_s() + 1234.5;
    const SatelliteState s = KeplerSatelliteState(e, t);
    EXPECT_LT((s.velocity_ecef_m_s - NumericVelocity(e, t)).norm(), 1e-5) << e.sat.ToString();
    const double h = 0.5;
    const double drift = (KeplerSatelliteState(e, t + h).clock_bias_s - KeplerSatelliteState(e, t - h).clock_bias_s) / (2 * h);
    EXPECT_NEAR(s.clock_drift_s_s, drift, 1e-16) << e.sat.ToString();
    ++checked;
  }
  EXPECT_EQ(checked, 4 + 16 + 8);
}

// A BeiDou GEO: broadcast in a frame inclined by 5° (B1I ICD §5.2.4.12). Built with i = 5° and its node
// at 180° in that frame, the −5° rotation puts it on the equator at every time: z ≈ 0 (the sign check),
// at the radius A (e = 0), keeping its longitude (geostationary: |v| ≈ 0 in ECEF).
KeplerEphemeris GeoExample() {
  KeplerEphemeris e;
  e.sat = {GnssSystem::kBeidou, 3};
  e.sqrt_a_sqrt_m = std::sqrt(42164.17e3);
  e.i0_rad = 5.0 * kDegToRad;
  e.week = 1000;  // BDT
  e.toe_s = 345600.0;
  e.omega0_rad = kPi + OrbitConstants(GnssSystem::kBeidou).omega_e_rad_s * e.toe_s;  // node 180° at toe
  e.m0_rad = 0.3;
  e.toc_gps_s = e.toe_gps_s();
  return e;
}

TEST(GnssOrbit, BeidouGeoIsRotatedOntoTheEquatorAndStaysPut) {
  const KeplerEphemeris e = GeoExample();
  ASSERT_TRUE(IsBeidouGeo(e.sat));
  EXPECT_TRUE(IsBeidouGeo({GnssSystem::kBeidou, 61}));
  EXPECT_FALSE(IsBeidouGeo({GnssSystem::kBeidou, 21}));
  EXPECT_FALSE(IsBeidouGeo({GnssSystem::kGps, 3}));
  for (double dt : {-3600.0, 0.0, 1800.0, 7200.0}) {
    const double t = e.toe_gps_s() + dt;
    const SatelliteState s = KeplerSatelliteState(e, t);
    EXPECT_NEAR(s.position_ecef_m.z(), 0.0, 1e-3) << dt;
    EXPECT_NEAR(s.position_ecef_m.norm(), 42164.17e3, 1e-3) << dt;
    // A = 42164.17 km is geostationary to 10 m in radius: drift below 1 m/s.
    EXPECT_LT(s.velocity_ecef_m_s.norm(), 1.0) << dt;
    EXPECT_LT((s.velocity_ecef_m_s - NumericVelocity(e, t)).norm(), 1e-5) << dt;
  }
  // The same elements read as a non-GEO (PRN 21) would be inclined by 10° and move fast: the branch matters.
  KeplerEphemeris meo = e;
  meo.sat.prn = 21;
  EXPECT_GT(std::abs(KeplerSatelliteState(meo, e.toe_gps_s() + 1800.0).position_ecef_m.z()), 1e5);
}

TEST(GnssOrbit, RelativisticTermMatchesItsClosedForm) {
  // Δt_r = F·e·√A·sin E equals −2 r·v/c² for a Keplerian orbit (r·v is the same in ECEF: ω×r ⟂ r). The
  // harmonic radius corrections add a radial rate up to 2·ν̇·√(Crs² + Crc²) (0.03-0.07 m/s here), which
  // r·v sees and F·e·√A·sin E does not: bound 2·|r|·that/c², + 10 % for ν̇ ≠ n.
  const RinexNav nav = BundledNav();
  for (const KeplerEphemeris& e : nav.kepler) {
    const double t = e.toe_gps_s() + 600.0;
    const SatelliteState s = KeplerSatelliteState(e, t);
    const double closed = -2.0 * s.position_ecef_m.dot(s.velocity_ecef_m_s) / (kSpeedOfLight * kSpeedOfLight);
    const double a = e.sqrt_a_sqrt_m * e.sqrt_a_sqrt_m;
    const double n = std::sqrt(OrbitConstants(e.sat.system).mu_m3_s2 / (a * a * a));
    const double bound = 1.1 * 2.0 * s.position_ecef_m.norm() * 2.0 * n * std::hypot(e.crs_m, e.crc_m) /
                         (kSpeedOfLight * kSpeedOfLight);
    EXPECT_NEAR(s.relativistic_s, closed, bound + 1e-12) << e.sat.ToString();
    EXPECT_NEAR(s.clock_bias_s - s.relativistic_s,
                e.af0_s + e.af1_s_s * (t - e.toc_gps_s) + e.af2_s_s2 * std::pow(t - e.toc_gps_s, 2), 1e-15);
  }
  // GPS's F = −4.442807633e-10 s/√m (IS-GPS-200 §20.3.3.3.3.1).
  EXPECT_NEAR(RelativisticClockTerm(GnssSystem::kGps, 0.01, 5153.7, kPi / 2.0), -4.442807633e-10 * 0.01 * 5153.7,
              1e-9 * 2.29e-8);  // the ICD's 10 digits
}

TEST(GnssOrbit, GroupDelayFollowsEachSystemsReferenceSignal) {
  KeplerEphemeris g;
  g.sat = {GnssSystem::kGps, 5};
  g.tgd_s = -1e-8;
  EXPECT_DOUBLE_EQ(GroupDelay(g, GnssSignal::kGpsL1Ca), -1e-8);
  EXPECT_NEAR(GroupDelay(g, GnssSignal::kGpsL2), -1e-8 * std::pow(77.0 / 60.0, 2), 1e-20);
  bool known = true;
  GroupDelay(g, GnssSignal::kGpsL5, &known);
  EXPECT_FALSE(known);
  KeplerEphemeris e;
  e.sat = {GnssSystem::kGalileo, 7};
  e.bgd_e5a_e1_s = 2e-9;
  e.bgd_e5b_e1_s = 3e-9;
  e.codes_on_l2 = 513;  // I/NAV E1-B (bit 0), E5b/E1 clock (bit 9)
  EXPECT_DOUBLE_EQ(GroupDelay(e, GnssSignal::kGalileoE1), 3e-9);
  e.codes_on_l2 = 258;  // F/NAV
  EXPECT_DOUBLE_EQ(GroupDelay(e, GnssSignal::kGalileoE1), 2e-9);
  KeplerEphemeris c;
  c.sat = {GnssSystem::kBeidou, 21};
  c.tgd1_b1_b3_s = 4e-9;
  c.tgd2_b2_b3_s = -2e-9;
  EXPECT_DOUBLE_EQ(GroupDelay(c, GnssSignal::kBeidouB1I), 4e-9);
  EXPECT_DOUBLE_EQ(GroupDelay(c, GnssSignal::kBeidouB2I), -2e-9);
  EXPECT_DOUBLE_EQ(GroupDelay(c, GnssSignal::kBeidouB3I, &known), 0.0);
  EXPECT_TRUE(known);
  EXPECT_DOUBLE_EQ(GroupDelay(c, GnssSignal::kBeidouB1C, &known), 0.0);
  EXPECT_FALSE(known);
}

TEST(GnssOrbit, SelectsTheClosestHealthyEphemerisInDate) {
  const RinexNav nav = BundledNav();
  // E08 has two F/NAV records (data sources 258), toe 17:10 and 17:20: at toe + 6 min the later is closer.
  const SatelliteId e08{GnssSystem::kGalileo, 8};
  const KeplerEphemeris* first = nullptr;
  for (const KeplerEphemeris& e : nav.kepler)
    if (e.sat == e08 && (!first || e.toe_gps_s() < first->toe_gps_s())) first = &e;
  ASSERT_NE(first, nullptr);
  EphemerisSelection fnav;
  fnav.galileo_inav = false;
  const KeplerEphemeris* at = SelectEphemeris(nav.kepler, e08, first->toe_gps_s() + 360.0, fnav);
  ASSERT_NE(at, nullptr);
  EXPECT_DOUBLE_EQ(at->toe_gps_s(), first->toe_gps_s() + 600.0);
  EXPECT_EQ(SelectEphemeris(nav.kepler, e08, first->toe_gps_s() + 240.0, fnav), first);
  // I/NAV (the default, for E1) asked of F/NAV-only records; out of date (> 4 h for Galileo); unknown
  // satellite; unhealthy.
  EXPECT_EQ(SelectEphemeris(nav.kepler, e08, first->toe_gps_s()), nullptr);
  EXPECT_EQ(SelectEphemeris(nav.kepler, e08, first->toe_gps_s() + 600.0 + 4.0 * 3600.0 + 1.0, fnav), nullptr);
  EXPECT_EQ(SelectEphemeris(nav.kepler, {GnssSystem::kGps, 18}, first->toe_gps_s()), nullptr);
  std::vector<KeplerEphemeris> sick = nav.kepler;
  for (KeplerEphemeris& e : sick) e.health = 1.0;
  EXPECT_EQ(SelectEphemeris(sick, e08, first->toe_gps_s(), fnav), nullptr);
}

TEST(GnssOrbit, TransmitTimeAndEarthRotation) {
  const RinexNav nav = BundledNav();
  const KeplerEphemeris& e = nav.kepler.front();
  const Vec3 rx(-1276969.0, -4717225.3, 4087226.7);
  const double t_rx = e.toe_gps_s() + 100.0;
  // A pseudorange made from the model itself (no receiver clock): the transmit time must reproduce it.
  double tau = 0.075;
  for (int i = 0; i < 5; ++i) {
    const SatelliteState s = KeplerSatelliteState(e, t_rx - tau);
    tau = (EarthRotationCorrection(s.position_ecef_m, OrbitConstants(e.sat.system).omega_e_rad_s, tau) - rx).norm() /
          kSpeedOfLight;
  }
  const SatelliteState at_tx = KeplerSatelliteState(e, t_rx - tau);
  const double p = kSpeedOfLight * (tau - at_tx.clock_bias_s);
  const TransmitState tx = SatelliteAtTransmit(e, t_rx, p, rx);
  EXPECT_NEAR(tx.tx_gps_s, t_rx - tau, 1e-11);
  EXPECT_NEAR(tx.travel_s, tau, 1e-11);
  EXPECT_NEAR((tx.sat.position_ecef_m - rx).norm(), kSpeedOfLight * tau, 1e-3);
  // The rotation Ω̇e·τ moves the satellite by ≈ Ω̇e·τ·(x, y) horizontally: ~ 20-40 m for a MEO.
  const double moved = (tx.sat.position_ecef_m - at_tx.position_ecef_m).norm();
  EXPECT_NEAR(moved, OrbitConstants(e.sat.system).omega_e_rad_s * tau * at_tx.position_ecef_m.head<2>().norm(), 1e-3);
}

}  // namespace
}  // namespace gins
