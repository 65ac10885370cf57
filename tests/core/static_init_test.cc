// Static initialisation fed from the seeded simulator: gyro bias, tilt and yaw against the exact truth,
// with the dual-antenna heading and from the first motion, and a log that never stands still.
#include "core/initializer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/geodesy.h"
#include "core/heading_model.h"
#include "core/sim/simulator.h"
#include "core/so3.h"
#include "core/wheel_model.h"
#include "test_scenarios.h"

namespace gins {
namespace GINS_TEST_FILE {

struct InitRun {
  bool done = false;
  InitResult result;
  NavState truth;  // at result.x0.t (the completing fix's epoch)
  GnssMeasurement completing_fix;
  std::string diagnosis;
  double elapsed_at_done = 0.0;  // seconds after the first record
  std::vector<std::pair<double, double>> heading_errors_deg;  // (t, error) of every valid heading fed
};

// Feeds the initialiser the drive's records, converted as the EstimatorPipeline converts them (world frame at the
// simulation's origin), until it completes or the drive ends.
InitRun Feed(const SimOptions& sim, const Options& options) {
  const double g_norm = NormalGravity(sim.origin.lat_deg, sim.origin.alt_m);
  const LocalEnuFrame frame(sim.origin);
  Initializer init(options.sensors, options.init, options.standstill, g_norm);
  Simulator simulator(sim);
  InitRun run;
  SimRecord rec;
  while (simulator.Next(&rec)) {
    if (const ImuSample* imu = rec.get_if<ImuSample>()) {
      init.AddImu(*imu);
    } else if (const WheelRecord* wheel = rec.get_if<WheelRecord>()) {
      const WheelOptions& wo = options.sensors.wheel;
      WheelMeasurement w;
      w.t = wheel->t;
      w.speed = 0.5 * (WheelSpeedFromPulses(wheel->left_pulses, wo.radius, wo.pulses_per_rev, wo.interval) +
                       WheelSpeedFromPulses(wheel->right_pulses, wo.radius, wo.pulses_per_rev, wo.interval));
      w.sigma = wo.speed_sigma;
      w.interval = wo.interval;
      w.standstill = wheel->left_pulses == 0.0 && wheel->right_pulses == 0.0;
      init.AddWheel(w);
    } else if (const GnssRecord* fix = rec.get_if<GnssRecord>()) {  // these drives have no GVEL
      const GnssRecord& g = *fix;
      GnssMeasurement m;
      m.t = g.t;
      m.p_w = frame.ToEnu({g.lat_deg, g.lon_deg, g.alt_m});
      m.sigma_w = g.has_sigma ? g.sigma_enu.cwiseMax(options.sensors.gnss.min_sigma) : options.sensors.gnss.sigma_enu;
      m.heading_valid = g.heading_valid;
      m.yaw_G = CompassDegToEnuYaw(g.heading_deg);
      m.sigma_yaw = options.sensors.gnss.heading_sigma;
      if (m.heading_valid) {
        const Mat3 R_wG = rec.truth.R_wb() * ExpMat(Vec3(0, 0, options.sensors.gnss.mount_yaw));
        run.heading_errors_deg.emplace_back(m.t, WrapAngle(m.yaw_G - YawOfXAxis<double>(R_wG)) * kRadToDeg);
      }
      init.AddGnss(m);
      if (init.done()) {
        run.done = true;
        run.result = init.result();
        run.truth = rec.truth;
        run.completing_fix = m;
        run.elapsed_at_done = g.t - sim.start_time;
        return run;
      }
    }
  }
  run.diagnosis = init.Diagnosis();
  return run;
}

double YawErrorDeg(const NavState& est, const NavState& truth) {
  return WrapAngle(YawOfXAxis<double>(est.R_wb()) - YawOfXAxis<double>(truth.R_wb())) * kRadToDeg;
}

// Angle (deg) between the body-frame "up" directions of two attitudes: the tilt error, yaw excluded.
double TiltErrorDeg(const Quat& q_est, const Quat& q_truth) {
  const Vec3 up_est = q_est.conjugate() * Vec3::UnitZ();
  const Vec3 up_true = q_truth.conjugate() * Vec3::UnitZ();
  return std::atan2(up_est.cross(up_true).norm(), up_est.dot(up_true)) * kRadToDeg;
}

// With the dual-antenna heading (TestDrive: 20 s standstill first, 5 % of the headings invalid).
//
// What bounds the errors (default init.static_duration_s = 2 s, so the first 2 s of the standstill):
// - gyro bias: the mean of 2 s of white noise, σ = 0.5 deg/√h / √(2 s) ≈ 21 deg/h per axis. Measured on
//   seeds 1-3: max |δbg| per axis 49.1 deg/h; threshold 4σ = 85 deg/h (a ~100 deg/h turn-on bias not removed
//   at all would be caught only marginally, so a second test uses a 15 s window: σ ≈ 7.7 deg/h).
// - tilt: at rest the horizontal accelerometer bias is indistinguishable from tilt, so the tilt error is
//   about |ba_horizontal|/g (TestDrive: 0.03 m/s² per axis, ~0.25 deg). Checked tightly against the tilt
//   that bias predicts; against the truth with the bias's 3-σ bound.
// - yaw: one heading fix, σ 0.2 deg: the yaw error must be that fix's error (measured to 0.0003 deg; the
//   noise-free drive gives 0.0003 deg), and below 4σ = 0.8 deg (measured 0.034, 0.046, 0.007 deg; 0.39 deg
//   at most over seeds 1-12).
// Tilt against the bias-predicted tilt: measured 0.0117, 0.0099, 0.0018 deg (at most 0.0117 over seeds 1-12;
// 0.0005 without sensor noise); the 2 s mean of the accelerometer noise gives σ ≈ 0.0034 deg per axis.
TEST(StaticInitializer, DualAntennaHeadingFromSimulatedStandstill) {
  for (unsigned seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const SimOptions sim = test::TestDrive(seed);
    const Options options = test::TestRunOptions(sim);
    const InitRun run = Feed(sim, options);
    ASSERT_TRUE(run.done) << run.diagnosis;
    const InitResult& r = run.result;
    EXPECT_EQ(r.heading_source, "dual_antenna");
    // Completed at a fix inside the standstill, soon after the 2 s window.
    EXPECT_GE(run.elapsed_at_done, options.init.static_duration - 0.05);
    EXPECT_LE(run.elapsed_at_done, 20.0);
    EXPECT_NEAR(r.static_end - r.static_start, options.init.static_duration, 0.05);

    const Vec3 dbg_deg_h = (r.x0.bg - run.truth.bg) * kRadToDeg * 3600.0;
    // Predicted tilt error from the true horizontal accelerometer bias: the mean specific force at rest is
    // R_wbᵀ·(0, 0, g) + ba, and the initialiser takes its direction as "up".
    const Vec3 f_b = run.truth.R_wb().transpose() * Vec3(0, 0, r.g_norm) + run.truth.ba;
    const Vec3 up_pred = f_b.normalized();
    const Vec3 up_est = r.x0.q_wb.conjugate() * Vec3::UnitZ();
    const double tilt_vs_pred_deg = std::atan2(up_est.cross(up_pred).norm(), up_est.dot(up_pred)) * kRadToDeg;
    const double tilt_deg = TiltErrorDeg(r.x0.q_wb, run.truth.q_wb);
    const double yaw_deg = YawErrorDeg(r.x0, run.truth);
    const double ba_h = Vec2(run.truth.ba.x(), run.truth.ba.y()).norm();
    std::printf(
        "seed %u: done at %.1f s, dbg [%.1f %.1f %.1f] deg/h, tilt %.4f deg (vs bias-predicted %.4f deg, "
        "|ba_h|/g %.4f deg), yaw %.4f deg, |dp| %.4f m, |dv| %.4f m/s\n",
        seed, run.elapsed_at_done, dbg_deg_h.x(), dbg_deg_h.y(), dbg_deg_h.z(), tilt_deg, tilt_vs_pred_deg,
        ba_h / r.g_norm * kRadToDeg, yaw_deg, (r.x0.p_wb - run.truth.p_wb).norm(), (r.x0.v_w - run.truth.v_w).norm());

    EXPECT_LT(dbg_deg_h.cwiseAbs().maxCoeff(), 85.0);
    EXPECT_LT(tilt_vs_pred_deg, 0.025);
    EXPECT_LT(tilt_deg, 3.0 * std::sqrt(2.0) * sim.acc_turn_on_bias / r.g_norm * kRadToDeg);  // 0.74 deg
    EXPECT_LT(std::abs(yaw_deg), 0.8);
    // The fit takes the yaw from the standstill's valid headings (each as good as the other at rest): its
    // error is their mean error.
    double heading_error_deg = 0.0;
    int n_headings = 0;
    for (const auto& [t, e] : run.heading_errors_deg) {
      if (t < r.static_start - 1e-6 || t > r.x0.t + 1e-6) continue;
      heading_error_deg += e;
      ++n_headings;
    }
    ASSERT_GT(n_headings, 0);
    EXPECT_NEAR(yaw_deg, heading_error_deg / n_headings, 0.01);
    // At rest at a fix: position from the fix and the lever arm (measured 0.065, 0.015, 0.034 m), velocity zero.
    EXPECT_LT((r.x0.p_wb - run.truth.p_wb).norm(), 0.15);
    EXPECT_LT(r.x0.v_w.norm(), 1e-6);
    EXPECT_TRUE(r.P0.allFinite());
    EXPECT_GT(r.P0.diagonal().minCoeff(), 0.0);
    // Noise levels at rest: the simulated white noise σ = density·√rate.
    EXPECT_NEAR(r.gyro_noise_density / sim.gyro_noise_density, 1.0, 0.15);
    EXPECT_NEAR(r.acc_noise_density / sim.acc_noise_density, 1.0, 0.15);
  }
}

// A longer standstill window averages the gyro noise down: σ ≈ 21 deg/h / √(15/2) ≈ 7.7 deg/h per axis.
// Measured max |δbg| per axis 18.3 deg/h (seeds 1-3); threshold 4σ ≈ 30 deg/h.
TEST(StaticInitializer, LongerStandstillGivesBetterGyroBias) {
  for (unsigned seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const SimOptions sim = test::TestDrive(seed);
    Options options = test::TestRunOptions(sim);
    options.init.static_duration = 15.0;
    const InitRun run = Feed(sim, options);
    ASSERT_TRUE(run.done) << run.diagnosis;
    const Vec3 dbg_deg_h = (run.result.x0.bg - run.truth.bg) * kRadToDeg * 3600.0;
    std::printf("seed %u: 15 s window, dbg [%.1f %.1f %.1f] deg/h, yaw %.4f deg\n", seed, dbg_deg_h.x(), dbg_deg_h.y(),
                dbg_deg_h.z(), YawErrorDeg(run.result.x0, run.truth));
    EXPECT_LT(dbg_deg_h.cwiseAbs().maxCoeff(), 30.0);
    EXPECT_EQ(run.result.heading_source, "dual_antenna");
    EXPECT_LT(std::abs(YawErrorDeg(run.result.x0, run.truth)), 0.8);  // measured 0.49, 0.08, 0.18 deg
  }
}

// No heading at all: the yaw comes from the first motion (GNSS track against the dead-reckoned track).
TEST(StaticInitializer, HeadingFromMotionWithoutDualAntenna) {
  for (unsigned seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    SimOptions sim = test::TestDrive(seed);
    sim.heading_invalid_fraction = 1.0;
    Options options = test::TestRunOptions(sim);
    options.sensors.gnss.use_heading = false;
    options.init.wait_for_heading = false;
    const InitRun run = Feed(sim, options);
    ASSERT_TRUE(run.done) << run.diagnosis;
    const InitResult& r = run.result;
    const double yaw_deg = YawErrorDeg(r.x0, run.truth);
    std::printf("seed %u: motion heading at %.1f s, yaw %.4f deg, tilt %.4f deg, |dv| %.4f m/s, |dp| %.4f m\n", seed,
                run.elapsed_at_done, yaw_deg, TiltErrorDeg(r.x0.q_wb, run.truth.q_wb),
                (r.x0.v_w - run.truth.v_w).norm(), (r.x0.p_wb - run.truth.p_wb).norm());
    EXPECT_EQ(r.heading_source, "motion");
    // Not before the vehicle moves (at 20 s), and within seconds of it (5 m of track at 1 m/s²).
    EXPECT_GT(run.elapsed_at_done, 20.0);
    EXPECT_LT(run.elapsed_at_done, 30.0);
    // Measured yaw -0.17, -0.32, -0.26 deg; |δv| 0.11, 0.12, 0.10 m/s (the wheel speed is the mean over the
    // last 0.1 s and carries the 1 % scale error); |δp| 0.016, 0.029, 0.026 m.
    EXPECT_LT(std::abs(yaw_deg), 1.0);
    EXPECT_LT((r.x0.v_w - run.truth.v_w).norm(), 0.25);
    EXPECT_LT((r.x0.p_wb - run.truth.p_wb).norm(), 0.1);
    // The yaw σ is the fit's (no longer a configured 5° floor): the error is within 4 σ of it, and it is
    // below the acceptance bound.
    const Vec3 z_b = r.x0.q_wb.conjugate() * Vec3::UnitZ();
    const double var_yaw = z_b.dot(r.P0.block<3, 3>(nav::kTheta, nav::kTheta) * z_b);
    EXPECT_LT(std::abs(yaw_deg), 4.0 * std::sqrt(var_yaw) * kRadToDeg);
    EXPECT_LE(std::sqrt(var_yaw), options.init.max_attitude_sigma * 1.001);
  }
}

// Waiting for a heading that never comes: not done, and the diagnosis says what it is waiting for.
TEST(StaticInitializer, WaitsForHeadingWhenConfiguredTo) {
  SimOptions sim = test::TestDrive(1);
  sim.heading_invalid_fraction = 1.0;
  sim.segments.resize(4);  // 20 s standstill then some driving
  Options options = test::TestRunOptions(sim);
  options.init.wait_for_heading = true;  // use_heading is true too
  const InitRun run = Feed(sim, options);
  EXPECT_FALSE(run.done);
  EXPECT_NE(run.diagnosis.find("standstill found"), std::string::npos) << run.diagnosis;
  EXPECT_NE(run.diagnosis.find("waiting for a valid dual-antenna heading"), std::string::npos) << run.diagnosis;
  EXPECT_NE(run.diagnosis.find("wait_for_heading"), std::string::npos) << run.diagnosis;
}

// A log that starts in motion and never stops: no standstill, so the joint fit of GNSS and IMU initialises
// in motion. (The IMU alone passes the "quiet" checks in the first seconds of a steady 1 m/s² acceleration:
// |mean specific force| − g is only ~0.05 m/s²; the wheels say it moves.) Before, this log was refused.
TEST(StaticInitializer, NeverStandingStillInitialisesInMotion) {
  SimOptions sim = test::TestDrive(1);
  const double d = kDegToRad;
  sim.segments = {
      {8.0, 1.0, 0.0, 0.0},       // accelerate from t = 0
      {15.0, 0.0, 6.0 * d, 0.0},  // left turn
      {10.0, -0.3, 0.0, 0.0},     // slow down, still moving
      {15.0, 0.0, -4.0 * d, 0.0},
  };
  sim.gnss_outages.clear();
  const Options options = test::TestRunOptions(sim);
  const InitRun run = Feed(sim, options);
  ASSERT_TRUE(run.done) << run.diagnosis;
  EXPECT_EQ(run.result.start, "moving");
  EXPECT_EQ(run.result.static_end, 0.0);
  EXPECT_LT(std::abs(YawErrorDeg(run.result.x0, run.truth)), 1.0);
}

}  // namespace
}  // namespace gins

namespace gins {
namespace GINS_TEST_FILE {

// When a fit starts the estimators (FitStartsEstimators): precise enough, or settled over a full window.
TEST(FitStartsEstimators, PreciseOrSettledOverAFullWindow) {
  constexpr double kDeg = kDegToRad;
  const double max_att = 1.0 * kDeg, max_tilt = 1.04 * kDeg;
  const auto fit = [](double yaw_deg, double tilt_deg, double runner_up, double inflation = 1.0) {
    AlignmentFit a;
    a.yaw_sigma = yaw_deg * kDegToRad;
    a.tilt_sigma = tilt_deg * kDegToRad;
    a.runner_up_delta_chi2 = runner_up;
    a.inflation = inflation;
    return a;
  };
  const double inf = std::numeric_limits<double>::infinity();
  // Precise: at any time, unless another yaw explains the window nearly as well (the inflated quantile).
  EXPECT_TRUE(FitStartsEstimators(fit(0.5, 0.5, inf), false, max_att, max_tilt));
  EXPECT_TRUE(FitStartsEstimators(fit(0.5, 0.5, 200.0, 10.0), false, max_att, max_tilt));
  EXPECT_FALSE(FitStartsEstimators(fit(0.5, 0.5, 100.0, 10.0), false, max_att, max_tilt));  // 15.1 × 10
  EXPECT_FALSE(FitStartsEstimators(fit(0.5, 1.2, inf), false, max_att, max_tilt));
  // Not precise: only once the window is full, with yaw σ ≤ 30° and roll/pitch σ ≤ 5° (a slow rover's
  // correlated fixes leave both above the precise limits).
  EXPECT_FALSE(FitStartsEstimators(fit(20.0, 0.5, inf), false, max_att, max_tilt));
  EXPECT_TRUE(FitStartsEstimators(fit(20.0, 0.5, inf), true, max_att, max_tilt));
  EXPECT_TRUE(FitStartsEstimators(fit(29.0, 1.5, inf), true, max_att, max_tilt));
  EXPECT_TRUE(FitStartsEstimators(fit(29.0, 4.9, inf), true, max_att, max_tilt));
  EXPECT_FALSE(FitStartsEstimators(fit(29.0, 5.1, inf), true, max_att, max_tilt));
  EXPECT_FALSE(FitStartsEstimators(fit(31.0, 0.5, inf), true, max_att, max_tilt));
  // Settled, but another yaw within the plain χ²(1) 99.99 % quantile (15.1) of the best: ambiguous.
  EXPECT_FALSE(FitStartsEstimators(fit(20.0, 0.5, 14.0, 10.0), true, max_att, max_tilt));
  EXPECT_TRUE(FitStartsEstimators(fit(20.0, 0.5, 16.0, 10.0), true, max_att, max_tilt));
}

}  // namespace
}  // namespace gins
