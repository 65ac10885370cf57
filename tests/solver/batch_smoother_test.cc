// The whole-log smoother (solver/batch_smoother.h) and the ESKF's RTS pass (solver/eskf_rts.h) end to end
// on seeded simulated drives: two-sided estimates through an outage, continuity of the IMU-rate output,
// agreement with the window when the window spans the drive, residuals at a noise-free truth, and σ
// against the Monte-Carlo spread.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "drive_harness.h"
#include "test_scenarios.h"

namespace gins {
namespace GINS_TEST_FILE {

using test::DriveRun;
using test::Errors;

// The largest jump between consecutive states at or after `from` beyond what their velocity explains (m).
double LargestJump(const std::vector<StateEstimate>& states, double from = -1e300) {
  double worst = 0.0;
  for (size_t i = 1; i < states.size(); ++i) {
    if (states[i - 1].x.t < from) continue;
    const double dt = states[i].x.t - states[i - 1].x.t;
    const Vec3 moved = states[i].x.p_wb - states[i - 1].x.p_wb;
    const Vec3 expected = 0.5 * (states[i].x.v_w + states[i - 1].x.v_w) * dt;
    worst = std::max(worst, (moved - expected).norm());
  }
  return worst;
}

void ExpectFiniteWithSigma(const std::vector<StateEstimate>& states, const char* what) {
  bool time_order = true, finite = true, positive = true;
  for (size_t i = 0; i < states.size(); ++i) {
    const StateEstimate& s = states[i];
    finite = finite && s.x.AllFinite() && s.sigma_p.allFinite() && s.sigma_v.allFinite() && s.sigma_att.allFinite();
    positive = positive && (s.sigma_p.array() > 0.0).all() && (s.sigma_att.array() > 0.0).all();
    if (i > 0) time_order = time_order && s.x.t >= states[i - 1].x.t;
  }
  EXPECT_TRUE(finite) << what;
  EXPECT_TRUE(positive) << what;
  EXPECT_TRUE(time_order) << what;
}

TEST(BatchEndToEnd, BridgesTheOutageFromBothSidesWithoutJumps) {
  const SimOptions sim = test::TestDrive(3);
  const Options options = test::TestRunOptions(sim);
  const DriveRun run = test::RunDriveThroughSession(sim, options, nullptr, true, true, true);
  ASSERT_TRUE(run.initialized);
  ASSERT_FALSE(run.batch.empty());
  ASSERT_FALSE(run.eskf_rts.empty());
  // Every IMU-rate state of the forward streams has its smoothed counterpart (the two-sided streams start
  // at the first fix, the forward ones at the standstill's first fix: a little later).
  const auto from_first_forward = [](const std::vector<StateEstimate>& two_sided, double t0) {
    return static_cast<size_t>(std::count_if(two_sided.begin(), two_sided.end(),
                                             [&](const StateEstimate& s) { return s.x.t >= t0 - 1e-9; }));
  };
  EXPECT_EQ(from_first_forward(run.batch, run.smoother.front().x.t), run.smoother.size());
  EXPECT_EQ(from_first_forward(run.eskf_rts, run.eskf.front().x.t), run.eskf.size());
  ExpectFiniteWithSigma(run.batch, "batch");
  ExpectFiniteWithSigma(run.eskf_rts, "eskf_rts");

  const double t0 = sim.start_time;
  const double out_from = t0 + sim.gnss_outages[0].first, out_to = out_from + sim.gnss_outages[0].second;
  const auto in_window = [&](const std::vector<StateEstimate>& s) { return Errors(run, s, out_from, out_to); };
  const auto outside = [&](const std::vector<StateEstimate>& s) {
    const double from = run.init_t + 5.0;
    test::DriveErrors before = Errors(run, s, from, out_from), after = Errors(run, s, out_to + 5.0);
    test::DriveErrors e;
    e.n = before.n + after.n;
    e.rmse_h = std::sqrt((before.rmse_h * before.rmse_h * before.n + after.rmse_h * after.rmse_h * after.n) / e.n);
    return e;
  };
  const test::DriveErrors window_out = in_window(run.smoother), batch_out = in_window(run.batch);
  const test::DriveErrors eskf_out = in_window(run.eskf), rts_out = in_window(run.eskf_rts);
  test::PrintErrors("window, outage", window_out);
  test::PrintErrors("batch, outage", batch_out);
  test::PrintErrors("eskf, outage", eskf_out);
  test::PrintErrors("eskf_rts, outage", rts_out);
  const double window_rmse = outside(run.smoother).rmse_h, batch_rmse = outside(run.batch).rmse_h;
  const double eskf_rmse = outside(run.eskf).rmse_h, rts_rmse = outside(run.eskf_rts).rmse_h;
  std::printf("outside the outage: window %.4f batch %.4f eskf %.4f eskf_rts %.4f m\n", window_rmse, batch_rmse,
              eskf_rmse, rts_rmse);
  const double jump_batch = LargestJump(run.batch, run.init_t), jump_rts = LargestJump(run.eskf_rts, run.init_t);
  const double jump_window = LargestJump(run.smoother);
  // Before the initialisation the backward run (solver/pre_init_backward.h) meets the first state within
  // that state's σ: its own data move its smoothed start a little.
  const double join_batch = LargestJump(run.batch), join_rts = LargestJump(run.eskf_rts);
  std::printf("largest jump: window %.4f batch %.4f eskf_rts %.4f m; with the backward run %.4f %.4f m\n",
              jump_window, jump_batch, jump_rts, join_batch, join_rts);
  for (const std::vector<StateEstimate>* two_sided : {&run.batch, &run.eskf_rts}) {
    const auto first = std::find_if(two_sided->begin(), two_sided->end(),
                                    [&](const StateEstimate& s) { return s.x.t >= run.init_t - 1e-9; });
    ASSERT_NE(first, two_sided->end());
    EXPECT_LT(LargestJump(*two_sided), first->sigma_p.norm());
  }

  // Two-sided: the worst error in the outage at least halved against the one-sided estimators.
  EXPECT_LT(batch_out.max_h, 0.5 * window_out.max_h);
  EXPECT_LT(rts_out.max_h, 0.5 * eskf_out.max_h);
  EXPECT_LT(batch_out.max_h, 0.25);
  EXPECT_LT(rts_out.max_h, 0.25);
  // And no worse where the GNSS is there.
  EXPECT_LT(batch_rmse, 1.05 * window_rmse);
  EXPECT_LT(rts_rmse, 1.05 * eskf_rmse);
  EXPECT_LT(batch_rmse, 0.02);
  EXPECT_LT(rts_rmse, 0.02);
  // The IMU-rate states are bridged onto both keyframes: no jump at either (a millimetre is the IMU's
  // own step-to-step discretisation at 100 Hz).
  EXPECT_LT(jump_batch, 2e-3);
  EXPECT_LT(jump_rts, 2e-3);
}

// With a window longer than the drive nothing is marginalised: the window's final estimate is the
// solution of the same factors the batch solves, so the two agree (both converged).
TEST(BatchEndToEnd, EqualsTheWindowWhenTheWindowSpansTheDrive) {
  SimOptions sim = test::TestDrive(5);
  sim.segments.resize(4);  // 60 s: standstill, acceleration, a turn, a hill
  sim.gnss_outages.clear();
  Options options = test::TestRunOptions(sim);
  options.smoother.window_size = 1000;
  options.smoother.max_iterations = 100;
  options.smoother.function_tolerance = 1e-12;
  options.batch.function_tolerance = 1e-12;
  options.batch.max_relinearizations = 0;  // the window's own linearisation points
  options.batch.revisit_fixes = false;     // and its own decisions
  options.smoother.bias_reintegrate_threshold = 1e9;  // the window never swaps a factor after its last solve
  const DriveRun run = test::RunDriveThroughSession(sim, options, nullptr, false, true, true);
  ASSERT_TRUE(run.initialized);
  ASSERT_EQ(run.batch.size(), run.smoother.size());
  // At the keyframes (the fixes, 1 Hz): between them the window propagates from each keyframe alone,
  // the batch bridges onto both.
  double worst_p = 0.0, worst_att = 0.0, t_att = 0.0;
  size_t keyframes = 0;
  for (size_t i = 0; i < run.batch.size(); ++i) {
    ASSERT_EQ(run.batch[i].x.t, run.smoother[i].x.t);
    // Before the initialisation the window writes the rest states (yaw unknown), the batch its first
    // state carried back (solver/pre_init_output.h): the solutions start at the initialisation.
    if (run.batch[i].x.t < run.init_t) continue;
    const double since_start = run.batch[i].x.t - sim.start_time;
    if (std::abs(since_start - std::round(since_start)) > 1e-6) continue;
    ++keyframes;
    worst_p = std::max(worst_p, (run.batch[i].x.p_wb - run.smoother[i].x.p_wb).norm());
    const double att = run.batch[i].x.q_wb.angularDistance(run.smoother[i].x.q_wb);
    if (att > worst_att) t_att = run.batch[i].x.t - sim.start_time;
    worst_att = std::max(worst_att, att);
  }
  std::printf("batch vs window at %zu keyframes: %.3g m, %.3g rad (at %.2f s)\n", keyframes, worst_p, worst_att,
              t_att);
  EXPECT_GT(keyframes, 50u);
  EXPECT_LT(worst_p, 1e-6);
  EXPECT_LT(worst_att, 1e-7);
}

// Noise-free sensors: the truth is a zero-residual point of every factor, so the batch's optimum has a
// cost near zero: below 5 % of a unit per factor, where measurement noise would leave about half a unit per
// residual (a wrong model, sign or lever arm in any factor leaves tens to thousands of units there).
TEST(BatchEndToEnd, NearZeroResidualsOnNoiseFreeSensors) {
  SimOptions sim = test::TestDrive(7);
  sim.gyro_noise_density = sim.acc_noise_density = 0.0;
  sim.gyro_bias_rw = sim.acc_bias_rw = 0.0;
  sim.gyro_turn_on_bias = sim.acc_turn_on_bias = 0.0;
  sim.gnss_sigma_enu = Vec3(1e-4, 1e-4, 1e-4);
  sim.heading_sigma = 1e-6;
  sim.wheel_speed_noise = 0.0;
  Options options = test::TestRunOptions(sim);
  nlohmann::json stats;
  const DriveRun run = test::RunDriveThroughSession(sim, options, nullptr, false, true, true);
  ASSERT_TRUE(run.initialized);
  const nlohmann::json& batch = run.stats["estimators"]["smoother"]["batch"];
  const double cost = batch["final_cost"].get<double>();
  const int factors = batch["factors"].get<int>();
  const test::DriveErrors e = Errors(run, run.batch, run.init_t);
  test::PrintErrors("batch, noise-free", e);
  std::printf("final cost %.4g over %d factors\n", cost, factors);
  EXPECT_LT(cost, 0.05 * factors);
  EXPECT_LT(e.max_h, 5e-3);
}

// Every fix is judged again on the two-sided solution with its covariance. An estimator told a much
// quieter IMU than the one it has is overconfident through an outage and rejects the true fixes that come
// back; the batch takes them (restored), and never the gross outliers (20 m), so it ends as accurate as
// on a log without them.
TEST(BatchEndToEnd, RevisitsTheWindowsFixDecisions) {
  SimOptions sim = test::TestDrive(9);
  sim.gnss_outages = {{125.0, 30.0}};
  sim.gyro_noise_density *= 4.0;
  sim.acc_noise_density *= 4.0;
  Options options = test::TestRunOptions(sim);
  options.sensors.imu.gyro_noise_density = sim.gyro_noise_density / 4.0;  // the estimator told the quieter IMU
  options.sensors.imu.acc_noise_density = sim.acc_noise_density / 4.0;
  const DriveRun clean = test::RunDriveThroughSession(sim, options, nullptr, false, true, true);
  sim.gnss_outlier_probability = 0.05;
  sim.gnss_outlier_magnitude = 20.0;
  const DriveRun dirty = test::RunDriveThroughSession(sim, options, nullptr, false, true, true);
  ASSERT_TRUE(clean.initialized && dirty.initialized);
  const nlohmann::json& c = clean.stats["estimators"]["smoother"];
  const nlohmann::json& d = dirty.stats["estimators"]["smoother"];
  std::printf("clean: window rejected %s, batch restored %d dropped %d\n", c["gnss_position"]["rejected"].dump().c_str(),
              c["batch"]["revisit_restored"].get<int>(), c["batch"]["revisit_dropped"].get<int>());
  std::printf("outliers: window rejected %s, batch restored %d dropped %d\n",
              d["gnss_position"]["rejected"].dump().c_str(), d["batch"]["revisit_restored"].get<int>(),
              d["batch"]["revisit_dropped"].get<int>());
  const test::DriveErrors ec = Errors(clean, clean.batch, clean.init_t + 5.0);
  const test::DriveErrors ed = Errors(dirty, dirty.batch, dirty.init_t + 5.0);
  test::PrintErrors("batch, clean", ec);
  test::PrintErrors("batch, with outliers", ed);
  test::PrintErrors("window, clean", Errors(clean, clean.smoother, clean.init_t + 5.0));
  EXPECT_GT(c["batch"]["revisit_restored"].get<int>(), 0);
  EXPECT_LT(ed.rmse_h, ec.rmse_h + 0.01);
  EXPECT_LT(ed.max_h, ec.max_h + 0.05);
}

// A log solved in overlapping segments joined by marginalised priors gives the one-problem solution: the
// seams do not show.
TEST(BatchEndToEnd, SegmentsDoNotShow) {
  const SimOptions sim = test::TestDrive(3);
  Options options = test::TestRunOptions(sim);
  const DriveRun whole = test::RunDriveThroughSession(sim, options, nullptr, false, true, true);
  options.batch.max_segment_keyframes = 100;  // ~240 keyframes: 3 segments, seams amid the fixes
  options.batch.segment_overlap_keyframes = 60;
  const DriveRun split = test::RunDriveThroughSession(sim, options, nullptr, false, true, true);
  ASSERT_TRUE(whole.initialized && split.initialized);
  EXPECT_EQ(whole.stats["estimators"]["smoother"]["batch"]["segments"].get<int>(), 1);
  const int segments = split.stats["estimators"]["smoother"]["batch"]["segments"].get<int>();
  EXPECT_GE(segments, 3);
  ASSERT_EQ(whole.batch.size(), split.batch.size());
  double worst_p = 0.0, worst_att = 0.0, worst_sigma = 0.0, t_p = 0.0, t_att = 0.0;
  for (size_t i = 0; i < whole.batch.size(); ++i) {
    const double dp = (whole.batch[i].x.p_wb - split.batch[i].x.p_wb).norm();
    const double datt = whole.batch[i].x.q_wb.angularDistance(split.batch[i].x.q_wb);
    if (dp > worst_p) t_p = whole.batch[i].x.t - sim.start_time;
    if (datt > worst_att) t_att = whole.batch[i].x.t - sim.start_time;
    worst_p = std::max(worst_p, dp);
    worst_att = std::max(worst_att, datt);
    worst_sigma = std::max(worst_sigma, (whole.batch[i].sigma_p - split.batch[i].sigma_p).cwiseAbs().maxCoeff());
  }
  std::printf("%d segments: position %.3g m (at %.2f s), attitude %.3g rad (at %.2f s), σ %.3g m from the "
              "one-problem solution\n", segments, worst_p, t_p, worst_att, t_att, worst_sigma);
  EXPECT_LT(worst_p, 2e-4);  // the bound is 1 mm
  EXPECT_LT(worst_att, 1e-5);
  EXPECT_LT(worst_sigma, 1e-3);
  EXPECT_LT(LargestJump(split.batch), 2e-3);
}

// The batch's σ is what its errors are: over seeded drives whose sensors have exactly the noise the
// estimator is told, the RMS of the horizontal error over σ (pooled over the drives and the keyframes of
// the drive, outage included) is 1 within 10 %.
TEST(BatchEndToEnd, SigmaAgreesWithTheMonteCarloSpread) {
  double sum_sq = 0.0;
  size_t count = 0;
  for (unsigned seed = 100; seed < 114; ++seed) {
    SimOptions sim = test::TestDrive(seed);
    sim.segments.resize(11);  // 157 s, the outage from 125 to 145 s
    sim.gnss_outages = {{125.0, 20.0}};
    sim.heading_invalid_fraction = 0.0;
    Options options = test::TestRunOptions(sim);
    // The estimator told the sensors' true noise.
    options.sensors.imu.gyro_noise_density = sim.gyro_noise_density;
    options.sensors.imu.acc_noise_density = sim.acc_noise_density;
    options.sensors.imu.gyro_bias_rw = sim.gyro_bias_rw;
    options.sensors.imu.acc_bias_rw = sim.acc_bias_rw;
    options.sensors.gnss.heading_sigma = sim.heading_sigma;
    options.sensors.wheel.enabled = false;  // the wheel and the vehicle models are not the simulator's noise
    options.sensors.vehicle.nonholonomic = false;
    const DriveRun run = test::RunDriveThroughSession(sim, options, nullptr, false, true, true);
    ASSERT_TRUE(run.initialized);
    size_t j = 0;
    for (const StateEstimate& s : run.batch) {
      if (s.x.t < run.init_t + 5.0 || std::fmod(s.x.t - sim.start_time + 1e-6, 1.0) > 2e-6) continue;  // 1 Hz
      while (j < run.truth_t.size() && run.truth_t[j] < s.x.t - 1e-7) ++j;
      if (j == run.truth_t.size() || std::abs(run.truth_t[j] - s.x.t) > 1e-7) continue;
      const Vec3 e = s.x.p_wb - run.truth[j].p_wb;
      for (int a = 0; a < 2; ++a) {
        sum_sq += (e[a] / s.sigma_p[a]) * (e[a] / s.sigma_p[a]);
        ++count;
      }
    }
  }
  const double ratio = std::sqrt(sum_sq / static_cast<double>(count));
  std::printf("horizontal error / σ: RMS %.3f over %zu samples\n", ratio, count);
  EXPECT_GT(ratio, 0.9);
  EXPECT_LT(ratio, 1.1);
}

}  // namespace
}  // namespace gins
