// Single-point positioning (core/gnss_spp.h) on the bundled walk excerpt against RTKLIB's own SPP, and its
// design matrix against numeric differences.
//
// Reference: RTKLIB 2.4.3 b34 (Debian's rtklib package), on data/rinex/walk_excerpt.obs and walk.nav:
//   rnx2rtkp -k spp.conf -p 0 -sys G,E,C -f 1 -m 15 -e -o ex.pos walk_excerpt.obs walk.nav
// with spp.conf = "pos1-ionoopt =brdc", "pos1-tropopt =saas", "out-timeform =tow", "out-outstat =residual"
// (rnx2rtkp's -p 0 leaves ionosphere and troposphere off unless asked). Its solution (ex.pos) and its
// residuals at it (ex.pos.stat, $SAT and $CLK lines) are below. Its signals: GPS and Galileo C1C, BeiDou C1P
// (B1C). The navigation file has no GPSA/GPSB, so rnx2rtkp's Klobuchar uses its built-in parameters
// (kRtklibAlpha/Beta); and its SPP leaves Galileo's BGD out (our galileo_group_delay = false).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "core/gnss_spp.h"
#include "core/io/rinex.h"

namespace gins {
namespace GINS_TEST_FILE {

const std::array<double, 4> kRtklibAlpha = {0.1118E-07, -0.7451E-08, -0.5961E-07, 0.1192E-06};
const std::array<double, 4> kRtklibBeta = {0.1167E+06, -0.2294E+06, -0.1311E+06, 0.1049E+07};

// ex.pos: x, y, z (m) of the 8 epochs.
const double kRtklibPosition[8][3] = {
    {-1276969.0431, -4717225.3202, 4087226.6960}, {-1276969.0615, -4717225.2977, 4087226.7215},
    {-1276969.0313, -4717225.3233, 4087226.7516}, {-1276969.0170, -4717225.2809, 4087226.7334},
    {-1276969.0536, -4717225.2810, 4087226.7725}, {-1276969.0301, -4717225.3785, 4087226.7270},
    {-1276969.0671, -4717225.4810, 4087226.8021}, {-1276969.0333, -4717225.3171, 4087226.7678}};
// ex.pos.stat, first epoch: $CLK receiver clock (GPS, ns) and Galileo/BeiDou offsets from it (ns); $SAT
// azimuth, elevation (deg) and residual (m) of the 15 satellites used.
constexpr double kRtklibClockGpsNs = -1542924.894, kRtklibGalMinusGpsNs = -4.654, kRtklibBdsMinusGpsNs = 5.456;
struct RtklibSat {
  const char* id;
  double az_deg, el_deg, residual_m;
};
const RtklibSat kRtklibSats[] = {
    {"G10", 331.0, 64.9, -0.0203}, {"G23", 64.1, 50.6, -3.8364}, {"G27", 259.7, 32.4, 3.0670},
    {"G32", 224.6, 56.6, 1.0838},  {"E07", 59.3, 67.6, 1.2311},  {"E13", 132.6, 26.3, 2.0115},
    {"E26", 126.4, 80.7, -1.0973}, {"E29", 211.7, 52.8, 0.5621}, {"E33", 315.3, 45.2, -2.1620},
    {"C21", 336.8, 74.7, 2.7404},  {"C22", 54.6, 32.9, 0.0174},  {"C34", 247.3, 58.0, 0.3860},
    {"C42", 259.1, 35.0, -8.3276}, {"C43", 311.2, 27.0, 4.2335}, {"C44", 176.8, 28.7, 0.7879}};

// The epoch's single-frequency code observations as rnx2rtkp -f 1 takes them.
std::vector<SppObservation> FirstFrequency(const RinexObsEpoch& epoch) {
  std::vector<SppObservation> out;
  for (const RinexSatelliteObs& s : epoch.satellites) {
    SppObservation o;
    o.sat = s.sat;
    const char* code = "C1C";
    const char* cn0 = "S1C";
    if (s.sat.system == GnssSystem::kGps) {
      o.signal = GnssSignal::kGpsL1Ca;
    } else if (s.sat.system == GnssSystem::kGalileo) {
      o.signal = GnssSignal::kGalileoE1;
    } else if (s.sat.system == GnssSystem::kBeidou) {
      o.signal = GnssSignal::kBeidouB1C;
      code = "C1P";
      cn0 = "S1P";
    } else {
      continue;
    }
    const RinexObservation* c = s.Find(code);
    if (!c) continue;
    o.pseudorange_m = c->value;
    if (const RinexObservation* q = s.Find(cn0)) o.cn0_dbhz = q->value;
    out.push_back(o);
  }
  return out;
}

SppOptions RtklibLike() {
  SppOptions o;
  o.elevation_mask_rad = 15.0 * kDegToRad;
  o.klobuchar_alpha = kRtklibAlpha;
  o.klobuchar_beta = kRtklibBeta;
  o.galileo_group_delay = false;
  return o;
}

Mat3 EcefToEnu(const Vec3& ecef) {
  const GeodeticRad g = EcefToGeodeticRad(ecef);
  const double sp = std::sin(g.lat), cp = std::cos(g.lat), sl = std::sin(g.lon), cl = std::cos(g.lon);
  Mat3 r;
  r << -sl, cl, 0, -sp * cl, -sp * sl, cp, cp * cl, cp * sl, sp;
  return r;
}

struct Excerpt {
  RinexNav nav;
  std::vector<RinexObsEpoch> epochs;
  Vec3 approx = Vec3::Zero();
};
Excerpt ReadExcerpt() {
  Excerpt x;
  const std::string dir = std::string(GINS_TEST_DATA_DIR) + "/rinex/";
  x.nav = ReadRinexNav(dir + "walk.nav", InputOptions{});
  RinexObsReader reader(dir + "walk_excerpt.obs", InputOptions{});
  const auto& a = reader.header().approx_position_ecef_m;
  x.approx = Vec3(a[0], a[1], a[2]);
  RinexObsEpoch e;
  while (reader.Next(&e)) x.epochs.push_back(e);
  return x;
}

TEST(GnssSpp, AgreesWithRtklibOnTheBundledExcerpt) {
  const Excerpt x = ReadExcerpt();
  ASSERT_EQ(x.epochs.size(), 8u);
  for (size_t k = 0; k < 8; ++k) {
    const SppSolution sol = SolveSpp(x.epochs[k].gps_s, FirstFrequency(x.epochs[k]), x.nav.kepler, RtklibLike(), x.approx);
    ASSERT_TRUE(sol.ok) << sol.why;
    int used = 0;
    for (const SppSatellite& s : sol.satellites) used += s.used;
    EXPECT_EQ(used, 15) << k;  // rnx2rtkp's ns
    const Vec3 ref(kRtklibPosition[k][0], kRtklibPosition[k][1], kRtklibPosition[k][2]);
    const Vec3 enu = EcefToEnu(ref) * (sol.position_ecef_m - ref);
    // Measured: |ΔE| ≤ 0.045, |ΔN| ≤ 0.035, |ΔU| ≤ 0.092 m on these epochs (over the 526 epochs both solve in
    // the whole walk: rms 0.025/0.031/0.18 m, max 0.10/0.11/0.49 m). The models agree to 0.3 mm (next test):
    // the rest is the weighting (RTKLIB's σ² has 1/sin(el), ours 1/sin²(el); its Galileo SISA class differs).
    // 3× the largest seen here per component, 0.15/0.15/0.3 m.
    EXPECT_LT(std::abs(enu.x()), 0.15) << k;
    EXPECT_LT(std::abs(enu.y()), 0.15) << k;
    EXPECT_LT(std::abs(enu.z()), 0.30) << k;
  }
}

TEST(GnssSpp, ModelMatchesRtklibsResidualsAtItsSolution) {
  const Excerpt x = ReadExcerpt();
  const RinexObsEpoch& e = x.epochs.front();
  const Vec3 r(kRtklibPosition[0][0], kRtklibPosition[0][1], kRtklibPosition[0][2]);
  const double ns = kSpeedOfLight * 1e-9;
  const std::map<GnssSystem, double> clock = {{GnssSystem::kGps, kRtklibClockGpsNs * ns},
                                              {GnssSystem::kGalileo, (kRtklibClockGpsNs + kRtklibGalMinusGpsNs) * ns},
                                              {GnssSystem::kBeidou, (kRtklibClockGpsNs + kRtklibBdsMinusGpsNs) * ns}};
  const std::vector<SppObservation> obs = FirstFrequency(e);
  SppOptions icd = RtklibLike();
  icd.galileo_group_delay = true;
  int matched = 0;
  for (const RtklibSat& ref : kRtklibSats) {
    SatelliteId id;
    ASSERT_TRUE(ParseSatelliteId(ref.id, &id));
    for (const SppObservation& o : obs) {
      if (o.sat != id) continue;
      const KeplerEphemeris* eph = SelectEphemeris(x.nav.kepler, id, e.gps_s);
      ASSERT_NE(eph, nullptr) << ref.id;
      const PseudorangePrediction p = PredictPseudorange(*eph, o, e.gps_s, r, clock.at(id.system), RtklibLike());
      // Seen: ≤ 0.3 mm (RTKLIB prints 0.1 mm, its clocks 1 ps = 0.3 mm): 2 mm.
      EXPECT_NEAR(p.corrected_m - p.predicted_m, ref.residual_m, 2e-3) << ref.id;
      EXPECT_NEAR(p.azel.az * kRadToDeg, ref.az_deg, 0.051) << ref.id;  // printed to 0.1°
      EXPECT_NEAR(p.azel.el * kRadToDeg, ref.el_deg, 0.051) << ref.id;
      // With the ICD's BGD the Galileo residuals move by exactly c·BGD(E1,E5b) (I/NAV).
      const PseudorangePrediction q = PredictPseudorange(*eph, o, e.gps_s, r, clock.at(id.system), icd);
      const double bgd = id.system == GnssSystem::kGalileo ? kSpeedOfLight * eph->bgd_e5b_e1_s : 0.0;
      EXPECT_NEAR((q.corrected_m - q.predicted_m) - (p.corrected_m - p.predicted_m), -bgd, 1e-6) << ref.id;
      ++matched;
    }
  }
  EXPECT_EQ(matched, 15);
}

TEST(GnssSpp, DesignMatrixMatchesNumericDifferences) {
  const Excerpt x = ReadExcerpt();
  const RinexObsEpoch& e = x.epochs.front();
  const Vec3 r(kRtklibPosition[0][0], kRtklibPosition[0][1], kRtklibPosition[0][2]);
  SppOptions geometry = RtklibLike();
  geometry.troposphere = false;
  geometry.ionosphere = IonosphereModel::kNone;
  int checked = 0;
  for (const SppObservation& o : FirstFrequency(e)) {
    const KeplerEphemeris* eph = SelectEphemeris(x.nav.kepler, o.sat, e.gps_s);
    if (!eph) continue;
    const double clk = -4.6e5;
    // Central differences of the whole prediction (geometry and Earth rotation re-evaluated), 1 m steps.
    // Without the atmosphere, the row leaves out only τ's dependence on the receiver (the Sagnac rotation
    // moves the satellite by Ω̇e·|r_xy|/c ≈ 5e-6 m per m): 1e-5. With it, also ∂T/∂h ≈ −T/8 km (pressure's
    // scale height), 3e-4/sin(el), and the elevation's change: checked to 1e-3/sin(el).
    for (const bool atmosphere : {false, true}) {
      const SppOptions opt = atmosphere ? RtklibLike() : geometry;
      const PseudorangePrediction p = PredictPseudorange(*eph, o, e.gps_s, r, clk, opt);
      const double tol = atmosphere ? 1e-3 / std::sin(p.azel.el) : 1e-5;
      for (int i = 0; i < 3; ++i) {
        Vec3 d = Vec3::Zero();
        d(i) = 1.0;
        const double num = (PredictPseudorange(*eph, o, e.gps_s, r + d, clk, opt).predicted_m -
                            PredictPseudorange(*eph, o, e.gps_s, r - d, clk, opt).predicted_m) / 2.0;
        EXPECT_NEAR(p.d_position(i), num, tol) << o.sat.ToString() << " " << i << " " << atmosphere;
      }
      const double num_clk = (PredictPseudorange(*eph, o, e.gps_s, r, clk + 1.0, opt).predicted_m -
                              PredictPseudorange(*eph, o, e.gps_s, r, clk - 1.0, opt).predicted_m) / 2.0;
      EXPECT_NEAR(num_clk, 1.0, 1e-9);
    }
    ++checked;
  }
  EXPECT_GE(checked, 15);
}

TEST(GnssSpp, StartsFromTheEarthsCentreAndRefusesTooFewSatellites) {
  const Excerpt x = ReadExcerpt();
  const RinexObsEpoch& e = x.epochs.front();
  const std::vector<SppObservation> obs = FirstFrequency(e);
  const SppSolution from_approx = SolveSpp(e.gps_s, obs, x.nav.kepler, RtklibLike(), x.approx);
  const SppSolution from_centre = SolveSpp(e.gps_s, obs, x.nav.kepler, RtklibLike());
  ASSERT_TRUE(from_centre.ok) << from_centre.why;
  EXPECT_LT((from_centre.position_ecef_m - from_approx.position_ecef_m).norm(), 1e-3);
  EXPECT_EQ(from_centre.clock_m.size(), 3u);
  // GPS alone: 4 satellites with ephemerides, 4 unknowns: solvable; three are not.
  std::vector<SppObservation> gps;
  for (const SppObservation& o : obs)
    if (o.sat.system == GnssSystem::kGps) gps.push_back(o);
  EXPECT_TRUE(SolveSpp(e.gps_s, gps, x.nav.kepler, RtklibLike(), x.approx).ok);
  std::vector<SppObservation> few(gps.begin(), gps.end());
  std::vector<SppObservation> three;
  for (const SppObservation& o : few)
    if (SelectEphemeris(x.nav.kepler, o.sat, e.gps_s) && three.size() < 3) three.push_back(o);
  const SppSolution bad = SolveSpp(e.gps_s, three, x.nav.kepler, RtklibLike(), x.approx);
  EXPECT_FALSE(bad.ok);
  EXPECT_NE(bad.why.find("too few"), std::string::npos);
}

TEST(GnssSpp, IonosphereFreeAndUncorrectedModesSolve) {
  const Excerpt x = ReadExcerpt();
  const RinexObsEpoch& e = x.epochs.front();
  std::vector<SppObservation> obs = FirstFrequency(e);
  // GPS L1/L5 and Galileo E1/E5a where both codes exist (their group delays: L5 not in LNAV, E5a not in
  // I/NAV, so the combination keeps an inter-signal bias of a few dm, as the document says).
  for (SppObservation& o : obs) {
    for (const RinexSatelliteObs& s : e.satellites) {
      if (s.sat != o.sat || o.sat.system == GnssSystem::kBeidou) continue;
      if (const RinexObservation* c5 = s.Find("C5Q")) {
        o.has_second = true;
        o.signal2 = o.sat.system == GnssSystem::kGps ? GnssSignal::kGpsL5 : GnssSignal::kGalileoE5a;
        o.pseudorange2_m = c5->value;
      }
    }
  }
  SppOptions opt = RtklibLike();
  const SppSolution klob = SolveSpp(e.gps_s, obs, x.nav.kepler, opt, x.approx);
  opt.ionosphere = IonosphereModel::kIonosphereFree;
  const SppSolution iflc = SolveSpp(e.gps_s, obs, x.nav.kepler, opt, x.approx);
  opt.ionosphere = IonosphereModel::kNone;
  const SppSolution none = SolveSpp(e.gps_s, obs, x.nav.kepler, opt, x.approx);
  ASSERT_TRUE(klob.ok && iflc.ok && none.ok);
  // All within the single-frequency SPP's scatter of one another (metres), not wildly off.
  EXPECT_LT((iflc.position_ecef_m - klob.position_ecef_m).norm(), 15.0);
  EXPECT_LT((none.position_ecef_m - klob.position_ecef_m).norm(), 15.0);
}

}  // namespace
}  // namespace gins
