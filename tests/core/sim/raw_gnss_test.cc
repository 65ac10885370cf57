// Raw GNSS simulator (core/sim/raw_gnss.h) on the bundled broadcast ephemerides (data/rinex/walk.nav):
// noise-free epochs give SolveSpp the truth back; with code noise the SPP errors match its covariance (NEES);
// the Doppler gives the receiver's velocity back and is the phase's rate; blocked windows; the seed; the file.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/config_loader.h"
#include "core/chi2.h"
#include "core/gnss_spp.h"
#include "core/io/rinex.h"
#include "core/sim/raw_gnss.h"
#include "core/sim/simulator.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kT0 = 1440437500.0;  // GPS s, 2025-08-28 17:31:40 GPST: walk.nav's records are in date

const std::vector<KeplerEphemeris>& Ephemerides() {
  static const std::vector<KeplerEphemeris> ephs =
      ReadRinexNav(std::string(GINS_TEST_DATA_DIR) + "/rinex/walk.nav", InputOptions{}).kepler;
  return ephs;
}

// WGS 84 geodetic (deg, deg, m) to ECEF.
Vec3 GeodeticToEcef(double lat_deg, double lon_deg, double h_m) {
  const double a = 6378137.0, f = 1.0 / 298.257223563, e2 = f * (2.0 - f);
  const double lat = lat_deg * kDegToRad, lon = lon_deg * kDegToRad;
  const double n = a / std::sqrt(1.0 - e2 * std::sin(lat) * std::sin(lat));
  return Vec3((n + h_m) * std::cos(lat) * std::cos(lon), (n + h_m) * std::cos(lat) * std::sin(lon),
              (n * (1.0 - e2) + h_m) * std::sin(lat));
}
const Vec3 kBoulderEcef = GeodeticToEcef(40.0967, -105.1472, 1580.0);

RawGnssSimOptions NoiseFree() {
  RawGnssSimOptions o;
  o.clock_drift_rw_s_s_sqrt_s = 0.0;
  o.code_sigma_a_m = o.code_sigma_b_m = 0.0;
  o.multipath_sigma_m = 0.0;
  o.doppler_sigma_m_s = 0.0;
  o.phase_sigma_m = 0.0;
  o.iono_residual_fraction = o.tropo_residual_fraction = 0.0;
  return o;
}

RawGnssTruth Static(double t) { return {t, kBoulderEcef, Vec3::Zero()}; }

// The epoch's code observations of signal `index` (0: the first band of each system) for SolveSpp.
std::vector<SppObservation> CodeObservations(const RinexObsEpoch& e, const RawGnssSimOptions& sim, size_t index) {
  std::vector<SppObservation> out;
  for (const RinexSatelliteObs& s : e.satellites) {
    const std::string& band = sim.signals.at(s.sat.system).at(index);
    SppObservation o;
    o.sat = s.sat;
    EXPECT_TRUE(RinexSignal(s.sat.system, band, &o.signal));
    const RinexObservation* c = s.Find("C" + band);
    if (!c) continue;
    o.pseudorange_m = c->value;
    o.cn0_dbhz = s.Find("S" + band)->value;
    out.push_back(o);
  }
  return out;
}

SppOptions SppLike(const RawGnssSimOptions& sim) {
  SppOptions o;
  o.elevation_mask_rad = sim.elevation_mask_deg * kDegToRad;
  o.klobuchar_alpha = sim.Alpha();
  o.klobuchar_beta = sim.Beta();
  o.troposphere = true;
  o.galileo_group_delay = true;
  o.selection = sim.selection;
  return o;
}

TEST(RawGnss, NoiseFreeEpochGivesSppTheTruth) {
  const RawGnssSimOptions sim = NoiseFree();
  RawGnssSimulator simulator(Ephemerides(), sim, 1);
  const RinexObsEpoch e = simulator.Simulate(Static(kT0));
  EXPECT_EQ(e.gps_s, kT0 + sim.clock_bias_s);
  ASSERT_GE(e.satellites.size(), 15u);
  for (size_t band = 0; band < 2; ++band) {  // each frequency on its own: group delays and 1/f² per signal
    const SppSolution sol = SolveSpp(e.gps_s, CodeObservations(e, sim, band), Ephemerides(), SppLike(sim));
    ASSERT_TRUE(sol.ok) << sol.why;
    EXPECT_LT((sol.position_ecef_m - kBoulderEcef).norm(), 0.01) << band;
    ASSERT_EQ(sol.clock_m.size(), 3u);
    for (const auto& [system, clock_m] : sol.clock_m) {
      EXPECT_NEAR(clock_m, kSpeedOfLight * simulator.clock_bias_s(), 0.03) << static_cast<char>(system) << band;
    }
  }
  // The atmosphere is in the pseudoranges: SolveSpp without it is metres off.
  SppOptions no_atmosphere = SppLike(sim);
  no_atmosphere.troposphere = false;
  no_atmosphere.ionosphere = IonosphereModel::kNone;
  const SppSolution off = SolveSpp(e.gps_s, CodeObservations(e, sim, 0), Ephemerides(), no_atmosphere);
  ASSERT_TRUE(off.ok);
  EXPECT_GT((off.position_ecef_m - kBoulderEcef).norm(), 1.0);
}

// Code noise alone, SolveSpp's error budget set to it: the position NEES over 200 independent epochs sums to
// χ²(600); its mean is within the two-sided 99.9 % bounds of that distribution.
TEST(RawGnss, SppErrorsMatchTheirCovariance) {
  RawGnssSimOptions sim = NoiseFree();
  sim.code_sigma_a_m = sim.code_sigma_b_m = 0.3;
  RawGnssSimulator simulator(Ephemerides(), sim, 42);
  SppOptions spp = SppLike(sim);
  spp.sigma.a_m = sim.code_sigma_a_m;
  spp.sigma.b_m = sim.code_sigma_b_m;
  spp.klobuchar_sigma_fraction = 0.0;
  spp.troposphere_sigma_m = 0.0;
  spp.code_bias_sigma_m = 0.0;
  spp.ephemeris_sigma = false;
  constexpr int kEpochs = 200;
  double nees_sum = 0.0;
  for (int k = 0; k < kEpochs; ++k) {
    const RinexObsEpoch e = simulator.Simulate(Static(kT0 + 5.0 * k));
    const SppSolution sol = SolveSpp(e.gps_s, CodeObservations(e, sim, 0), Ephemerides(), spp);
    ASSERT_TRUE(sol.ok) << sol.why;
    const Vec3 err = sol.position_ecef_m - kBoulderEcef;
    const Mat3 cov = sol.covariance.topLeftCorner<3, 3>();
    nees_sum += err.dot(cov.ldlt().solve(err));
  }
  const double mean = nees_sum / kEpochs;
  EXPECT_GT(mean, Chi2Quantile(0.0005, 3 * kEpochs) / kEpochs);
  EXPECT_LT(mean, Chi2Quantile(0.9995, 3 * kEpochs) / kEpochs);
}

// A receiver moving at (10, −5, 1) m/s: least squares on −λ·D = u·(v_sat − v_rx) + c·(ḋt_r − ḋt_sv), the
// satellite from SatelliteAtTransmit, gives the velocity and the clock drift back.
TEST(RawGnss, DopplerGivesTheVelocityBack) {
  const RawGnssSimOptions sim = NoiseFree();
  RawGnssSimulator simulator(Ephemerides(), sim, 3);
  const Vec3 v_rx_ecef(10.0, -5.0, 1.0);
  const RinexObsEpoch e = simulator.Simulate({kT0, kBoulderEcef, v_rx_ecef});
  std::vector<Eigen::RowVector4d> rows;
  std::vector<double> y;
  for (const RinexSatelliteObs& s : e.satellites) {
    const std::string& band = sim.signals.at(s.sat.system)[0];
    GnssSignal signal;
    ASSERT_TRUE(RinexSignal(s.sat.system, band, &signal));
    const KeplerEphemeris* eph = SelectEphemeris(Ephemerides(), s.sat, e.gps_s, sim.selection);
    ASSERT_NE(eph, nullptr);
    const TransmitState tx = SatelliteAtTransmit(*eph, e.gps_s, s.Find("C" + band)->value, kBoulderEcef);
    const Vec3 u = (tx.sat.position_ecef_m - kBoulderEcef).normalized();
    const double lambda = kSpeedOfLight / SignalFrequency(signal);
    rows.push_back(Eigen::RowVector4d(-u.x(), -u.y(), -u.z(), 1.0));
    y.push_back(-lambda * s.Find("D" + band)->value - u.dot(tx.sat.velocity_ecef_m_s) +
                kSpeedOfLight * tx.sat.clock_drift_s_s);
  }
  ASSERT_GE(rows.size(), 8u);
  Eigen::MatrixXd h(rows.size(), 4);
  Eigen::VectorXd b(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    h.row(static_cast<Eigen::Index>(i)) = rows[i];
    b(static_cast<Eigen::Index>(i)) = y[i];
  }
  const Eigen::Vector4d x = h.colPivHouseholderQr().solve(b);
  EXPECT_LT((x.head<3>() - v_rx_ecef).norm(), 0.01) << x.transpose();
  EXPECT_NEAR(x(3), kSpeedOfLight * sim.clock_drift_s_s, 0.01);
}

// The Doppler is −(dL/dt)·… exactly: against the 5-point derivative of the simulated phase (h = 1 s: its
// truncation error is far below 1e-4 m/s), with the atmosphere off (the Doppler leaves its slow rates out).
TEST(RawGnss, DopplerIsThePhaseRate) {
  RawGnssSimOptions sim = NoiseFree();
  sim.ionosphere = sim.troposphere = false;
  RawGnssSimulator simulator(Ephemerides(), sim, 4);
  const Vec3 v_rx_ecef(10.0, -5.0, 1.0);
  std::vector<RinexObsEpoch> e;
  for (int k = -2; k <= 2; ++k) e.push_back(simulator.Simulate({kT0 + k, kBoulderEcef + k * v_rx_ecef, v_rx_ecef}));
  int checked = 0;
  for (const RinexSatelliteObs& s : e[2].satellites) {
    const std::string band = sim.signals.at(s.sat.system)[0];
    double l[5];
    bool all = true;
    for (int k = 0; k < 5; ++k) {
      const RinexSatelliteObs* found = nullptr;
      for (const RinexSatelliteObs& o : e[k].satellites) found = o.sat == s.sat ? &o : found;
      all = all && found;
      if (found) l[k] = found->Find("L" + band)->value;
    }
    if (!all) continue;
    GnssSignal signal;
    ASSERT_TRUE(RinexSignal(s.sat.system, band, &signal));
    const double lambda = kSpeedOfLight / SignalFrequency(signal);
    const double rate_cycles_s = (l[0] - 8.0 * l[1] + 8.0 * l[3] - l[4]) / 12.0;
    EXPECT_NEAR(-lambda * s.Find("D" + band)->value, lambda * rate_cycles_s, 5e-4) << s.sat.ToString();
    ++checked;
  }
  EXPECT_GE(checked, 15);
}

TEST(RawGnss, BlockedWindowsKeepTheHighest) {
  RawGnssSimOptions sim = NoiseFree();
  RawGnssSimulator open(Ephemerides(), sim, 5);
  sim.blocked = {{10.0, 20.0, 4}, {40.0, 5.0, 0}};
  RawGnssSimulator blocked(Ephemerides(), sim, 5);
  RinexObsEpoch previous;
  for (int k = 0; k < 60; ++k) {
    const RinexObsEpoch all = open.Simulate(Static(kT0 + k));
    const RinexObsEpoch some = blocked.Simulate(Static(kT0 + k));
    ASSERT_GT(all.satellites.size(), 10u);
    if (k >= 10 && k < 30) {
      ASSERT_EQ(some.satellites.size(), 4u) << k;
      // The four are the highest of all: each one's C/N0 (30 + 20 sin el) is above every one left out.
      double lowest_kept = 1e9;
      for (const RinexSatelliteObs& s : some.satellites) lowest_kept = std::min(lowest_kept, s.obs[3].value);
      int above = 0;
      for (const RinexSatelliteObs& s : all.satellites) above += s.obs[3].value >= lowest_kept;
      EXPECT_EQ(above, 4) << k;
    } else if (k >= 40 && k < 45) {
      EXPECT_TRUE(some.satellites.empty()) << k;
    } else {
      EXPECT_EQ(some.satellites.size(), all.satellites.size()) << k;
    }
    // A new ambiguity (LLI 1 on the phase) exactly where a satellite was not in the previous epoch.
    int relocked = 0;
    for (const RinexSatelliteObs& s : some.satellites) {
      bool before = false;
      for (const RinexSatelliteObs& p : previous.satellites) before = before || p.sat == s.sat;
      for (const RinexObservation& o : s.obs) {
        EXPECT_EQ(o.lli, o.code[0] == 'L' && !before ? 1 : 0) << k << " " << s.sat.ToString() << " " << o.code;
      }
      relocked += !before;
    }
    if (k == 30) {
      EXPECT_GE(relocked, 5);
    }
    if (k == 45) {
      EXPECT_EQ(relocked, static_cast<int>(some.satellites.size()));
    }
    previous = some;
  }
}

TEST(RawGnss, RefusesWhatItHasNoModelFor) {
  RawGnssSimOptions sim;
  sim.signals = {{GnssSystem::kGps, {"1C", "9Z"}}};
  EXPECT_THROW(RawGnssSimulator(Ephemerides(), sim, 1), std::invalid_argument);
  sim.signals = {{GnssSystem::kGlonass, {"1C"}}};
  EXPECT_THROW(RawGnssSimulator(Ephemerides(), sim, 1), std::invalid_argument);
  sim = RawGnssSimOptions{};
  sim.multipath_tau_s = 0.0;
  EXPECT_THROW(RawGnssSimulator(Ephemerides(), sim, 1), std::invalid_argument);
  RawGnssSimulator ok(Ephemerides(), RawGnssSimOptions{}, 1);
  ok.Simulate(Static(kT0));
  EXPECT_THROW(ok.Simulate(Static(kT0)), std::invalid_argument);  // time must advance
}

std::vector<RinexObsEpoch> SimulateRun(uint64_t seed, int epochs) {
  RawGnssSimulator simulator(Ephemerides(), RawGnssSimOptions{}, seed);
  std::vector<RinexObsEpoch> out;
  for (int k = 0; k < epochs; ++k) out.push_back(simulator.Simulate(Static(kT0 + k)));
  return out;
}

bool SameValues(const std::vector<RinexObsEpoch>& a, const std::vector<RinexObsEpoch>& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k) {
    if (a[k].gps_s != b[k].gps_s || a[k].satellites.size() != b[k].satellites.size()) return false;
    for (size_t s = 0; s < a[k].satellites.size(); ++s) {
      const auto &x = a[k].satellites[s], &y = b[k].satellites[s];
      if (x.sat != y.sat || x.obs.size() != y.obs.size()) return false;
      for (size_t o = 0; o < x.obs.size(); ++o) {
        if (x.obs[o].code != y.obs[o].code || x.obs[o].value != y.obs[o].value || x.obs[o].lli != y.obs[o].lli ||
            x.obs[o].ssi != y.obs[o].ssi) {
          return false;
        }
      }
    }
  }
  return true;
}

TEST(RawGnss, SeedRepeatsBitForBit) {
  const std::vector<RinexObsEpoch> a = SimulateRun(11, 20), b = SimulateRun(11, 20), c = SimulateRun(12, 20);
  EXPECT_TRUE(SameValues(a, b));
  EXPECT_FALSE(SameValues(a, c));
  EXPECT_NE(a[5].satellites[0].obs[0].value, c[5].satellites[0].obs[0].value);
}

TEST(RawGnss, WritesAFileTheReaderGivesBack) {
  const std::string path = test::MakeTempDir("raw_gnss") + "/obs.rnx";
  RawGnssSimulator writer_sim(Ephemerides(), RawGnssSimOptions{}, 21);
  RawGnssFileOptions file;
  file.start_gps_s = kT0;
  file.end_gps_s = kT0 + 9.5;
  file.rate_hz = 2.0;
  EXPECT_EQ(WriteSimulatedRinexObs(path, &writer_sim, file, Static), 20u);
  RawGnssSimulator direct(Ephemerides(), RawGnssSimOptions{}, 21);
  RinexObsReader reader(path, InputOptions{});
  EXPECT_EQ(reader.header().interval_s, 0.5);
  EXPECT_EQ(reader.header().obs_types, RawGnssObsTypes(RawGnssSimOptions{}));
  RinexObsEpoch e;
  int n = 0;
  while (reader.Next(&e)) {
    const RinexObsEpoch want = direct.Simulate(Static(kT0 + 0.5 * n++));
    EXPECT_NEAR(e.gps_s, want.gps_s, 3e-7);
    ASSERT_EQ(e.satellites.size(), want.satellites.size());
    for (size_t s = 0; s < want.satellites.size(); ++s) {
      ASSERT_EQ(e.satellites[s].obs.size(), want.satellites[s].obs.size());
      for (size_t o = 0; o < want.satellites[s].obs.size(); ++o) {
        EXPECT_NEAR(e.satellites[s].obs[o].value, want.satellites[s].obs[o].value, 5.0001e-4);
      }
    }
  }
  EXPECT_EQ(n, 20);
}

// gins simulate with simulate.raw_gnss_*: obs.rnx of the antenna (lever arm, ECEF from w, GPS times) that
// SolveSpp turns back into the antenna's truth while the vehicle drives.
TEST(RawGnss, SimulateWritesTheAntennasObservations) {
  const Options options = LoadOptionsFromString(
      "simulate:\n  start_time_s: 1440437500\n  origin: [40.0967, -105.1472, 1580.0]\n"
      "  segments: [{duration_s: 5}, {duration_s: 10, accel_m_s2: 1.0, yaw_rate_deg_s: 5}]\n"
      "  raw_gnss_enabled: true\n  raw_gnss_nav_file: \"" GINS_TEST_DATA_DIR "/rinex/walk.nav\"\n"
      "  raw_gnss_clock_drift_rw_s_s_sqrt_s: 0\n  raw_gnss_code_sigma_a_m: 0\n  raw_gnss_code_sigma_b_m: 0\n"
      "  raw_gnss_multipath_sigma_m: 0\n  raw_gnss_iono_residual_fraction: 0\n"
      "  raw_gnss_tropo_residual_fraction: 0\n  raw_gnss_galileo_signals: \"\"\n"
      "  raw_gnss_blocked: [{start_s: 3, duration_s: 2, max_visible: 0}]\n",
      "raw.yaml");
  const SimOptions& sim = options.simulate;
  ASSERT_TRUE(sim.raw_gnss.enabled);
  ASSERT_EQ(sim.raw_gnss.options.blocked.size(), 1u);
  EXPECT_EQ(sim.raw_gnss.options.blocked[0].max_visible, 0);
  EXPECT_EQ(RawGnssSignalsFromText(sim.raw_gnss).count(GnssSystem::kGalileo), 0u);
  const std::string dir = test::MakeTempDir("raw_gnss_simulate");
  EXPECT_EQ(Simulate(sim, dir).raw_gnss_epochs, 14u);  // 0..15 s but the outage's 3 and 4
  const TruthTrajectory truth(sim);
  const Vec3 r0_ecef = GeodeticToEcef(40.0967, -105.1472, 1580.0);
  RinexObsReader reader(dir + "/obs.rnx", InputOptions{});
  RawGnssSimOptions raw = sim.raw_gnss.options;
  raw.signals = RawGnssSignalsFromText(sim.raw_gnss);
  RinexObsEpoch e;
  int epochs = 0;
  while (reader.Next(&e)) {
    for (const RinexSatelliteObs& s : e.satellites) ASSERT_NE(s.sat.system, GnssSystem::kGalileo);
    const double t = kT0 + std::round(e.gps_s - kT0);  // the true time: the clock is 0.1 ms ahead
    const SppSolution sol = SolveSpp(e.gps_s, CodeObservations(e, raw, 0), Ephemerides(), SppLike(raw));
    ASSERT_TRUE(sol.ok) << sol.why;
    const TruthState x = truth.At(t);
    // The antenna in ECEF: the w frame is the ENU frame at the origin.
    const double lat = 40.0967 * kDegToRad, lon = -105.1472 * kDegToRad;
    Mat3 R_ecef_w;
    R_ecef_w.col(0) = Vec3(-std::sin(lon), std::cos(lon), 0.0);
    R_ecef_w.col(1) = Vec3(-std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat));
    R_ecef_w.col(2) = Vec3(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat));
    const Vec3 antenna_ecef = r0_ecef + R_ecef_w * (x.p_wb + x.q_wb.toRotationMatrix() * sim.lever_b);
    EXPECT_LT((sol.position_ecef_m - antenna_ecef).norm(), 0.02) << t - kT0;
    ++epochs;
  }
  EXPECT_EQ(epochs, 14);
}

}  // namespace
}  // namespace gins
