// The ESKF end to end on seeded simulated drives: accuracy against the exact truth, and an honest
// covariance (NEES inside a χ² band).
#include "solver/eskf.h"

#include <gtest/gtest.h>

#include "core/chi2.h"
#include "core/heading_model.h"
#include "core/sim/simulator.h"
#include "core/so3.h"
#include "estimators_from_options.h"
#include "solver/estimator_pipeline.h"
#include "sim_feed.h"
#include "test_scenarios.h"

namespace gins {
namespace GINS_TEST_FILE {

struct DriveResult {
  double rmse_h = 0, max_h = 0, rmse_v = 0, rmse_vel = 0, rmse_yaw_deg = 0, max_h_outage = 0;
  double mean_nees = 0;
  int nees_samples = 0;
  uint64_t gnss_used = 0;
  Vec3 final_bg_err = Vec3::Zero();
  double final_scale = 0;
};

bool InOutage(const SimOptions& sim, double t, double after) {
  for (const auto& [start, dur] : sim.gnss_outages) {
    const double s = t - sim.start_time;
    if (s >= start && s < start + dur + after) return true;
  }
  return false;
}

DriveResult RunDrive(const SimOptions& sim, const Options& options) {
  Simulator simulator(sim);
  EstimatorPipeline session(options.sensors, options.init, options.standstill);
  auto eskf_owned = test::MakeEskf(options, nullptr);
  Eskf* eskf = eskf_owned.get();
  session.AddEstimator(std::move(eskf_owned));

  DriveResult r;
  double sum_h2 = 0, sum_v2 = 0, sum_vel2 = 0, sum_yaw2 = 0, sum_nees = 0;
  int n = 0;
  double last_nees_t = -1e9;
  SimRecord rec;
  while (simulator.Next(&rec)) {
    test::FeedSession(&session, rec);
    if (!rec.is<ImuSample>() || !session.initialized()) continue;
    const NavState& x = eskf->state();
    const NavState& truth = rec.truth;
    const Vec3 dp = x.p_wb - truth.p_wb;
    const bool outage = InOutage(sim, x.t, 5.0);
    if (outage) {
      r.max_h_outage = std::max(r.max_h_outage, dp.head<2>().norm());
    } else {
      sum_h2 += dp.head<2>().squaredNorm();
      r.max_h = std::max(r.max_h, dp.head<2>().norm());
      sum_v2 += dp.z() * dp.z();
      sum_vel2 += (x.v_w - truth.v_w).squaredNorm();
      const double dyaw = WrapAngle(YawOfXAxis<double>(x.R_wb()) - YawOfXAxis<double>(truth.R_wb()));
      sum_yaw2 += dyaw * dyaw;
      ++n;
    }
    // NEES of (δp, δv, δθ) every 5 s (samples closer than that are strongly correlated), once the
    // deliberately generous initial covariance has been forgotten (60 s).
    if (x.t - last_nees_t >= 5.0 && x.t - sim.start_time > 60.0) {
      last_nees_t = x.t;
      const Vec15 e = truth.Boxminus(x);
      const Vec9 e9 = e.head<9>();
      const Mat9 P9 = eskf->covariance().topLeftCorner<9, 9>();
      sum_nees += e9.dot(P9.ldlt().solve(e9));
      ++r.nees_samples;
    }
  }
  session.Finish();
  r.rmse_h = std::sqrt(sum_h2 / n);
  r.rmse_v = std::sqrt(sum_v2 / n);
  r.rmse_vel = std::sqrt(sum_vel2 / n);
  r.rmse_yaw_deg = std::sqrt(sum_yaw2 / n) * kRadToDeg;
  r.mean_nees = sum_nees / r.nees_samples;
  r.final_bg_err = eskf->state().bg - rec.truth.bg;
  r.final_scale = eskf->odom_scale();
  return r;
}

// With the default (deliberately conservative) configuration: accuracy.
TEST(EskfEndToEnd, SimulatedDriveAccuracy) {
  for (unsigned seed : {1u, 2u}) {
    const SimOptions sim = test::TestDrive(seed);
    const DriveResult r = RunDrive(sim, test::TestRunOptions(sim));
    RecordProperty("rmse_h_seed" + std::to_string(seed), std::to_string(r.rmse_h));
    std::printf("seed %u: rmse_h %.4f m (max %.4f), rmse_v %.4f m, vel %.4f m/s, yaw %.4f deg, outage drift %.3f m, "
                "NEES %.2f over %d, scale %.4f, bg err %.1f deg/h\n",
                seed, r.rmse_h, r.max_h, r.rmse_v, r.rmse_vel, r.rmse_yaw_deg, r.max_h_outage, r.mean_nees,
                r.nees_samples, r.final_scale, r.final_bg_err.norm() * kRadToDeg * 3600);
    EXPECT_LT(r.rmse_h, 0.03);
    EXPECT_LT(r.max_h, 0.15);
    EXPECT_LT(r.rmse_v, 0.05);
    EXPECT_LT(r.rmse_vel, 0.03);
    EXPECT_LT(r.rmse_yaw_deg, 0.15);
    EXPECT_LT(r.max_h_outage, 1.0);
    EXPECT_NEAR(r.final_scale, 0.99, 0.003);
  }
}

// With the noise model equal to the simulated sensors: the covariance must be honest.
TEST(EskfEndToEnd, SimulatedDriveConsistency) {
  for (unsigned seed : {3u, 4u, 5u}) {
    const SimOptions sim = test::TestDrive(seed);
    Options options = test::TestRunOptions(sim);
    options.sensors.imu.gyro_noise_density = sim.gyro_noise_density;
    options.sensors.imu.acc_noise_density = sim.acc_noise_density;
    options.sensors.imu.gyro_bias_rw = sim.gyro_bias_rw;
    options.sensors.imu.acc_bias_rw = sim.acc_bias_rw;
    options.sensors.gnss.heading_sigma = sim.heading_sigma;
    options.sensors.wheel.speed_sigma = sim.wheel_speed_noise;
    const DriveResult r = RunDrive(sim, options);
    std::printf("seed %u: NEES %.2f over %d samples, rmse_h %.4f\n", seed, r.mean_nees, r.nees_samples, r.rmse_h);
    // Mean NEES of a 9-dof error over K independent samples is χ²(9K)/K. Samples 5 s apart still share
    // slowly varying bias and attitude errors, so count half of them as independent. 99.9 % band.
    const int K = r.nees_samples / 2;
    EXPECT_GT(r.mean_nees, Chi2Quantile(0.0005, 9 * K) / K);
    EXPECT_LT(r.mean_nees, Chi2Quantile(0.9995, 9 * K) / K);
  }
}

// The covariance stepped over intervals of several samples (eskf.covariance_interval_s) against every
// sample: the same trajectory to millimetres and σ within a few per cent, at 100 Hz (two samples per
// interval) and at 400 Hz (eight). The σ written inside an interval is the one at its start, so it may
// lag by the growth over one interval; the per-sample run is the reference.
TEST(EskfEndToEnd, CovarianceIntervalMatchesPerSample) {
  for (const double imu_rate : {100.0, 400.0}) {
    SimOptions sim = test::TestDrive(6);
    sim.imu_rate = imu_rate;
    const auto run = [&](double interval) {
      Options options = test::TestRunOptions(sim);
      options.eskf.covariance_interval = interval;
      std::vector<StateEstimate> states;
      Simulator simulator(sim);
      EstimatorPipeline session(options.sensors, options.init, options.standstill);
      session.AddEstimator(test::MakeEskf(options, [&](const StateEstimate& e) { states.push_back(e); }));
      SimRecord rec;
      while (simulator.Next(&rec)) test::FeedSession(&session, rec);
      session.Finish();
      return states;
    };
    const std::vector<StateEstimate> every = run(0.0), interval = run(0.02);
    ASSERT_EQ(every.size(), interval.size());
    ASSERT_GT(every.size(), static_cast<size_t>(180 * imu_rate));
    double max_dp = 0, min_ratio = 1e9, max_ratio = 0, sum_log_ratio = 0;
    int n = 0;
    for (size_t i = 0; i < every.size(); ++i) {
      ASSERT_EQ(every[i].x.t, interval[i].x.t);
      max_dp = std::max(max_dp, (every[i].x.p_wb - interval[i].x.p_wb).norm());
      for (const auto& [a, b] : {std::pair{every[i].sigma_p, interval[i].sigma_p},
                                 std::pair{every[i].sigma_v, interval[i].sigma_v},
                                 std::pair{every[i].sigma_att, interval[i].sigma_att}}) {
        const Vec3 r = b.cwiseQuotient(a);
        min_ratio = std::min(min_ratio, r.minCoeff());
        max_ratio = std::max(max_ratio, r.maxCoeff());
        sum_log_ratio += r.array().log().sum();
        n += 3;
      }
    }
    const double mean_ratio = std::exp(sum_log_ratio / n);
    std::printf("imu %.0f Hz: max position difference %.2g m, sigma ratio %.4f..%.4f (geometric mean %.5f)\n",
                imu_rate, max_dp, min_ratio, max_ratio, mean_ratio);
    EXPECT_LT(max_dp, 0.005);
    EXPECT_GT(min_ratio, 0.9);
    EXPECT_LT(max_ratio, 1.03);
    EXPECT_NEAR(mean_ratio, 1.0, 0.01);
  }
}

}  // namespace
}  // namespace gins
