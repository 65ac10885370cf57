// Tightly coupled GNSS end to end (solver/eskf_raw_gnss.cc, solver/estimator_pipeline_raw.cc): the ESKF's
// rows against numeric differences on the NavState manifold; a simulated drive whose log has no fixes, only
// raw epochs simulated for its antenna from real broadcast ephemerides (core/sim/raw_gnss.h,
// data/rinex/walk.nav): the ESKF's error and σ against the truth, the smoother's (pseudoranges, Dopplers and
// carrier phases differenced in time, solver/raw_gnss_attacher.h), the counts; and an urban canyon (3
// satellites for 60 s), where single-point fixes stop and both estimators still take the 3 satellites.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/io/rinex.h"
#include "core/sim/raw_gnss.h"
#include "drive_harness.h"
#include "solver/eskf_raw_gnss.h"
#include "solver/eskf_state.h"
#include "solver/raw_gnss_feed.h"
#include "test_scenarios.h"

namespace gins {
namespace GINS_TEST_FILE {

const RinexNav& WalkNav() {
  static const RinexNav nav = ReadRinexNav(std::string(GINS_TEST_DATA_DIR) + "/rinex/walk.nav", InputOptions{});
  return nav;
}

TEST(EskfRawGnss, RowsMatchNumericDifferencesOnTheManifold) {
  auto nav = std::make_shared<RawGnssNav>();
  RawGnssMeasurement m;
  m.nav = nav;
  const LocalEnuFrame frame({40.0967, -105.1472, 1580.0});
  m.origin_ecef = frame.OriginEcef();
  m.R_ecef_w = frame.R_ecef_w();
  std::vector<RawSatellite> sats(3);
  sats[0].r_sat_ecef = Vec3(-12.0e6, -14.0e6, 18.0e6), sats[0].v_sat_ecef = Vec3(1800.0, -900.0, 2400.0);
  sats[1].r_sat_ecef = Vec3(5.0e6, -20.0e6, 16.0e6), sats[1].v_sat_ecef = Vec3(-2500.0, 300.0, 1200.0);
  sats[2].r_sat_ecef = Vec3(-20.0e6, -5.0e6, 15.0e6), sats[2].v_sat_ecef = Vec3(700.0, 2900.0, -400.0);
  std::vector<const RawSatellite*> list;
  for (RawSatellite& s : sats) {
    s.sat.system = GnssSystem::kGps;
    s.range_m = 2.2e7, s.has_rate = true, s.rate_m_s = 100.0, s.range_sigma_m = 1.0, s.rate_sigma_m_s = 0.1;
    list.push_back(&s);
  }
  NavState x;
  x.p_wb = Vec3(30.0, -12.0, 2.0);
  x.v_w = Vec3(8.0, 3.0, -0.2);
  x.q_wb = Quat(Eigen::AngleAxisd(0.7, Vec3(0.2, -0.3, 0.9).normalized()));
  const Vec3 lever_b(0.8, -0.4, 1.2), omega_b(0.1, -0.2, 0.6);
  for (const bool rates : {false, true}) {
    const NuisanceRows rows = RawGnssRows(x, lever_b, omega_b, m, list, rates);
    ASSERT_EQ(rows.H.cols(), eskf::kDim);
    for (int k = 0; k < nav::kDim; ++k) {
      Vec15 d = Vec15::Zero();
      // Steps far above the round-off of a 2e7 m range (~4e-9 m), small for the curvature.
      const double h = k >= 6 && k < 9 ? 1e-3 : 1e-2;
      d[k] = h;
      const VecX numeric = (RawGnssRows(x.Boxplus(d), lever_b, omega_b, m, list, rates).r -
                            RawGnssRows(x.Boxplus(-d), lever_b, omega_b, m, list, rates).r) /
                           (2.0 * h);
      // The line of sight turns with the antenna position: ∂(u·Δv)/∂r ~ |Δv|/ρ ≈ 1e-4/m, neglected for rates.
      const double tol = rates && (k < 3 || k >= 6) ? 5e-4 : 2e-5;  // δθ moves the antenna too
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(rows.H(i, k), numeric(i), tol) << "rates " << rates << " col " << k;
    }
    for (int k = nav::kDim; k < eskf::kDim; ++k) EXPECT_EQ(rows.H.col(k).norm(), 0.0);
  }
}

// A drive near Boulder on 2025-08-28 ~17:30 GPST, when walk.nav's ephemerides are in date: the log has IMU
// records and no fixes and no wheels; the raw epochs (1 Hz) are simulated for its antenna.
SimOptions RawDrive(unsigned seed) {
  SimOptions sim = test::TestDrive(seed);
  sim.start_time = 1440437450.0;
  sim.origin = {40.0967, -105.1472, 1580.0};
  sim.earth_rotation = true;
  sim.gnss_rate = 0.0;  // no fixes in the log
  sim.wheel_rate = 0.0;
  sim.gnss_outages.clear();
  return sim;
}

Options RawOptions(const SimOptions& sim) {
  Options o = test::TestRunOptions(sim);
  o.sensors.wheel.enabled = false;
  o.sensors.wheel.interval = 0.1;  // TestRunOptions' 1/wheel_rate: no wheels here
  o.sensors.gnss.use_heading = false;
  o.sensors.gravity.earth_rotation = true;
  return o;
}

RawGnssSimOptions RawSim() {
  RawGnssSimOptions s;
  // Dual-frequency pairs whose group delays the records give exactly: L1/L2, E1/E5a (F/NAV), B1I/B3I.
  s.signals = {{GnssSystem::kGps, {"1C", "2L"}}, {GnssSystem::kGalileo, {"1C", "5Q"}},
               {GnssSystem::kBeidou, {"2I", "6I"}}};
  s.selection.galileo_inav = false;
  return s;
}

GnssRawOptions RawInput() {
  GnssRawOptions o;
  o.ionosphere = GnssRawOptions::Ionosphere::kIonosphereFree;
  o.elevation_mask = 10.0 * kDegToRad;
  // The simulator's Doppler noise (0.05 m/s at every elevation) as the model states it at the zenith.
  o.doppler_sigma = 0.025;
  return o;
}

// Raw epochs of the antenna (truth p + R·lever, v + R·(ω × lever)) at 1 Hz, handed to the session before
// the records at or after their time; with `loose`, each epoch becomes its single-point fix instead (what a
// receiver's own solver would log), or nothing when it has none. `stamped_late`: the log's clock (the IMU's)
// is that much behind GPS time, so the epoch measured at log time t is on GPS time t + stamped_late.
test::RecordHook WithRawEpochs(const SimOptions& sim, const RawGnssSimOptions& raw, bool loose,
                               double stamped_late = 0.0) {
  auto nav = std::make_shared<const RawGnssNav>(MakeRawGnssNav(WalkNav(), RawInput()));
  auto simulator = std::make_shared<RawGnssSimulator>(WalkNav().kepler, raw, 21);
  auto frame = std::make_shared<LocalEnuFrame>(sim.origin);
  auto truth = std::make_shared<TruthTrajectory>(sim);
  auto next = std::make_shared<double>(sim.start_time + 1.0);
  const Vec3 lever_b = sim.lever_b;
  return [=](const SimRecord& rec, const std::function<void(const SimRecord&)>& feed, EstimatorPipeline& session) {
    while (*next <= rec.t() && *next < truth->end_time()) {
      const TruthState x = truth->At(*next);
      const Mat3 R_wb = x.q_wb.toRotationMatrix();
      const Vec3 p_w = x.p_wb + R_wb * lever_b, v_w = x.v_w + R_wb * x.omega_b.cross(lever_b);
      const RinexObsEpoch e = simulator->Simulate(
          {*next + stamped_late, frame->OriginEcef() + frame->R_ecef_w() * p_w, frame->R_ecef_w() * v_w});
      RawGnssMeasurement m;
      m.rx_gps_s = m.t = e.gps_s;
      m.nav = nav;
      m.satellites = SelectSignals(e.satellites, *nav);
      if (!loose) {
        session.AddRawGnss(m);
      } else {
        std::vector<SppObservation> code;
        for (const RawGnssObservation& o : m.satellites) code.push_back(o.code);
        const SppSolution sol = SolveSpp(m.rx_gps_s, code, nav->ephemerides, nav->spp);
        if (sol.ok) {
          const GeodeticRad g = EcefToGeodeticRad(sol.position_ecef_m);
          GnssRecord f;
          f.t = m.rx_gps_s - sol.clock_m.begin()->second / kSpeedOfLight;
          f.lat_deg = g.lat * kRadToDeg, f.lon_deg = g.lon * kRadToDeg, f.alt_m = g.h;
          f.has_sigma = true;
          f.sigma_enu = Vec3::Constant(std::sqrt(sol.covariance.topLeftCorner<3, 3>().trace() / 3.0));
          session.AddGnss(f);
        }
      }
      *next += 1.0;
    }
    feed(rec);
  };
}

TEST(RawGnss, TightlyCoupledDriveWithoutFixes) {
  const SimOptions sim = RawDrive(31);
  const Options options = RawOptions(sim);
  const test::DriveRun run = test::RunDriveThroughSession(sim, options, WithRawEpochs(sim, RawSim(), false));
  ASSERT_TRUE(run.initialized);
  const double from = run.init_t + 20.0;
  const test::DriveErrors eskf = test::Errors(run, run.eskf, from);
  const test::DriveErrors smoother = test::Errors(run, run.smoother, from);
  test::PrintErrors("eskf (tight)", eskf);
  test::PrintErrors("smoother (tight)", smoother);
  // The ESKF's horizontal error is within its own σ: at least 95 % of the states inside 3 σ.
  size_t n = 0, inside = 0;
  test::ForEachAtTruth(run, run.eskf, from, 1e300, [&](const StateEstimate& s, size_t j) {
    const Vec3 d = s.x.p_wb - run.truth[j].p_wb;
    ++n;
    inside += std::abs(d.x()) <= 3.0 * s.sigma_p.x() && std::abs(d.y()) <= 3.0 * s.sigma_p.y();
  });
  EXPECT_GE(static_cast<double>(inside), 0.95 * static_cast<double>(n));
  // Pseudoranges of metre-level noise over ~20 satellites, Dopplers and phases: decimetres, far below one
  // satellite's σ (measured 0.32 m), and the velocity to millimetres per second (measured 5.7 mm/s).
  EXPECT_LT(eskf.rmse_h, 0.6);
  EXPECT_LT(eskf.rmse_vel, 0.02);
  // The smoother on the same (measured 0.288 m, 2.0 mm/s).
  EXPECT_LT(smoother.rmse_h, 0.6);
  EXPECT_LT(smoother.rmse_vel, 0.02);
  const nlohmann::json& in_smoother = run.stats["estimators"]["smoother"]["gnss_raw"];
  EXPECT_GT(in_smoother["ranges"]["used"].get<uint64_t>(), 150u) << in_smoother.dump();
  EXPECT_GT(in_smoother["range_rates"]["used"].get<uint64_t>(), 150u) << in_smoother.dump();
  EXPECT_GT(in_smoother["phase_differences"]["used"].get<uint64_t>(), 150u) << in_smoother.dump();
  EXPECT_GT(in_smoother["satellites_used"].get<uint64_t>(), 150u * 10u) << in_smoother.dump();
  const nlohmann::json& raw = run.stats["estimators"]["eskf"]["gnss_raw"];
  EXPECT_GT(raw["ranges"]["used"].get<uint64_t>(), 150u) << raw.dump();
  EXPECT_GT(raw["range_rates"]["used"].get<uint64_t>(), 150u) << raw.dump();
  EXPECT_GT(raw["phase_differences"]["used"].get<uint64_t>(), 150u) << raw.dump();
  EXPECT_TRUE(raw["ranges"]["rejected"].empty()) << raw.dump();
  EXPECT_EQ(run.stats["gnss_raw"]["epochs_without_fix"].get<uint64_t>(), 0u);
}

// A log whose clock is 0.2 s behind GPS time (the IMU stamped by a logger's clock): the RINEX epochs are
// 0.2 s later than the IMU time of their measurement, 2-3 m along the track at the drive's speed. Stated as
// gnss.time_offset_s, the raw epochs are put on the IMU's clock and the drive is as accurate as one stamped
// right (TightlyCoupledDriveWithoutFixes: below 0.6 m); held at 0 it is not.
TEST(RawGnss, AStatedTimeOffsetPutsTheEpochsOnTheImuClock) {
  const SimOptions sim = RawDrive(31);
  constexpr double kLate = 0.2;
  auto run_with = [&](double stated) {
    Options options = RawOptions(sim);
    options.sensors.gnss.time_offset = stated;
    options.sensors.gnss.estimate_time_offset = false;
    const test::DriveRun run =
        test::RunDriveThroughSession(sim, options, WithRawEpochs(sim, RawSim(), false, kLate));
    EXPECT_TRUE(run.initialized);
    return run;
  };
  const test::DriveRun stated = run_with(kLate);
  const test::DriveRun ignored = run_with(0.0);
  ASSERT_TRUE(stated.initialized && ignored.initialized);
  auto errors = [](const char* label, const test::DriveRun& run, const std::vector<StateEstimate>& states) {
    const test::DriveErrors e = test::Errors(run, states, run.init_t + 20.0);
    test::PrintErrors(label, e);
    return e;
  };
  const test::DriveErrors eskf = errors("eskf (offset stated)", stated, stated.eskf);
  const test::DriveErrors smoother = errors("smoother (offset stated)", stated, stated.smoother);
  const test::DriveErrors eskf_ignored = errors("eskf (offset ignored)", ignored, ignored.eskf);
  EXPECT_LT(eskf.rmse_h, 0.6);
  EXPECT_LT(smoother.rmse_h, 0.6);
  EXPECT_GT(eskf_ignored.rmse_h, 2.0 * eskf.rmse_h);
}

TEST(RawGnss, UrbanCanyonDriftsFarLessTightlyThanLoosely) {
  const SimOptions sim = RawDrive(32);
  const Options options = RawOptions(sim);
  RawGnssSimOptions raw = RawSim();
  // 60 s with the 3 highest satellites only, from 120 s into the drive (the cruise and the long turn).
  raw.blocked = {{119.0, 60.0, 3}};
  const test::DriveRun tight = test::RunDriveThroughSession(sim, options, WithRawEpochs(sim, raw, false));
  const test::DriveRun loose = test::RunDriveThroughSession(sim, options, WithRawEpochs(sim, raw, true));
  ASSERT_TRUE(tight.initialized && loose.initialized);
  const double t0 = sim.start_time + 120.0, t1 = t0 + 60.0;
  const test::DriveErrors in_tight = test::Errors(tight, tight.eskf, t0, t1);
  const test::DriveErrors in_loose = test::Errors(loose, loose.eskf, t0, t1);
  test::PrintErrors("canyon, tight", in_tight);
  test::PrintErrors("canyon, loose", in_loose);
  const test::DriveErrors window_tight = test::Errors(tight, tight.smoother, t0, t1);
  const test::DriveErrors window_loose = test::Errors(loose, loose.smoother, t0, t1);
  test::PrintErrors("canyon, smoother tight", window_tight);
  test::PrintErrors("canyon, smoother loose", window_loose);
  ASSERT_GT(in_tight.n, 1000u);
  // The phases' time differences hold the motion where 3 high satellites' pseudoranges and Dopplers could
  // not (without them: 2.96 m against 4.85 m); measured 0.30 m against 4.85 m (seed 32).
  EXPECT_LT(in_tight.max_h, in_loose.max_h / 3.0);
  EXPECT_LT(in_tight.rmse_h, in_loose.rmse_h / 3.0);
  // The smoother likewise (measured 0.184 m against 2.53 m; without the phases 1.57 m).
  EXPECT_LT(window_tight.max_h, window_loose.max_h / 3.0);
  EXPECT_LT(window_tight.rmse_h, window_loose.rmse_h / 3.0);
  // The canyon's epochs were used (no single-point fix there: too few satellites).
  const uint64_t after_init = tight.stats["gnss_raw"]["epochs_used"].get<uint64_t>() -
                              tight.stats["gnss_raw"]["epochs_to_initialization"].get<uint64_t>();
  for (const char* estimator : {"eskf", "smoother"}) {
    const nlohmann::json& counts = tight.stats["estimators"][estimator]["gnss_raw"];
    EXPECT_GE(counts["ranges"]["used"].get<uint64_t>() + 2, after_init) << estimator;
    EXPECT_GE(counts["phase_differences"]["used"].get<uint64_t>() + 3, after_init) << estimator;
  }
  EXPECT_EQ(tight.stats["gnss_raw"]["fix_failures"]["too few satellites"].get<uint64_t>(), 60u);
}

// An IMU glitch while driving without fixes (2 s of accelerometer x reading 20 m/s² too much, say a
// saturated or corrupted sensor) throws both estimators tens of metres off with the covariance of a good
// IMU: every epoch's ranges fail the gate from then on. After watchdog.max_reject_s of rejected epochs
// the watchdog re-initialises each from the epoch's own single-point fix, as it does from a logged fix,
// and the ranges bring it back to decimetres. Without the watchdog the run stays lost.
TEST(RawGnss, WatchdogReinitialisesALostTightlyCoupledRun) {
  const SimOptions sim = RawDrive(33);
  const double glitch = sim.start_time + 75.0;
  auto run_with = [&](bool watchdog, double glitch_acc) {
    Options options = RawOptions(sim);
    options.watchdog.enabled = watchdog;
    const test::RecordHook raw = WithRawEpochs(sim, RawSim(), false);
    const test::RecordHook hook = [&](const SimRecord& rec, const std::function<void(const SimRecord&)>& feed,
                                      EstimatorPipeline& session) {
      if (!rec.is<ImuSample>() || rec.t() < glitch || rec.t() >= glitch + 2.0) return raw(rec, feed, session);
      SimRecord bad = rec;
      bad.get<ImuSample>().acc.x() += glitch_acc;
      raw(bad, feed, session);
    };
    return test::RunDriveThroughSession(sim, options, hook);
  };
  const test::DriveRun on = run_with(true, 20.0);
  const test::DriveRun off = run_with(false, 20.0);
  const test::DriveRun clean = run_with(true, 0.0);
  ASSERT_TRUE(on.initialized && off.initialized && clean.initialized);
  const double from = glitch + 50.0;
  for (const char* name : {"eskf", "smoother"}) {
    SCOPED_TRACE(name);
    const bool eskf = std::string(name) == "eskf";
    const test::DriveErrors after = test::Errors(on, eskf ? on.eskf : on.smoother, from);
    const test::DriveErrors lost = test::Errors(off, eskf ? off.eskf : off.smoother, from);
    const test::DriveErrors unhurt = test::Errors(clean, eskf ? clean.eskf : clean.smoother, from);
    test::PrintErrors((std::string(name) + " without the glitch").c_str(), unhurt);
    test::PrintErrors((std::string(name) + " after the reset").c_str(), after);
    test::PrintErrors((std::string(name) + " without the watchdog").c_str(), lost);
    const nlohmann::json& w = on.stats["estimators"][name]["watchdog"];
    std::printf("  %s watchdog %s, ranges %s\n", name, w.dump().c_str(),
                on.stats["estimators"][name]["gnss_raw"].dump().c_str());
    ASSERT_GE(w["count"].get<uint64_t>(), 1u);
    EXPECT_EQ(w["resets"][0]["reason"].get<std::string>(), "gnss_rejected");
    EXPECT_GT(w["resets"][0]["time"].get<double>(), glitch);
    EXPECT_LT(w["resets"][0]["time"].get<double>(), glitch + 2.0 + WatchdogOptions().max_reject + 3.0);
    EXPECT_EQ(clean.stats["estimators"][name]["watchdog"]["count"].get<uint64_t>(), 0u);
    // Back on the ranges: below the single-point fixes' metres (the reset's own error), and within the
    // estimate's own σ (at least 95 % of the states inside 3 σ horizontally). The clean drive, averaging
    // pseudoranges 50 s longer, is closer.
    EXPECT_LT(after.rmse_h, 1.0);
    size_t n = 0, inside = 0;
    test::ForEachAtTruth(on, eskf ? on.eskf : on.smoother, from, 1e300, [&](const StateEstimate& e, size_t j) {
      const Vec3 d = e.x.p_wb - on.truth[j].p_wb;
      ++n;
      inside += std::abs(d.x()) <= 3.0 * e.sigma_p.x() && std::abs(d.y()) <= 3.0 * e.sigma_p.y();
    });
    std::printf("  %s: %zu of %zu states within 3 sigma\n", name, inside, n);
    EXPECT_GE(static_cast<double>(inside), 0.95 * static_cast<double>(n));
    EXPECT_GT(lost.rmse_h, 10.0);
  }
}

}  // namespace
}  // namespace gins
