// Single-point GNSS whose errors are correlated in time (gnss.error_correlation_s, core/gnss_noise.h): on a
// simulated 20 Hz log with first-order Gauss–Markov position errors, both estimators' position σ must stay
// honest (normalised position errors of χ²(3) size), which independent fixes cannot give.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "drive_harness.h"
#include "test_scenarios.h"

namespace gins {
namespace GINS_TEST_FILE {

struct Nees {
  double eskf = 0.0, smoother = 0.0;
  double rmse_h_eskf = 0.0, rmse_h_smoother = 0.0;
};

// Mean of Σ_i (δp_i / σ_i)² over the world axes, sampled every 5 s from 60 s after initialisation (closer
// samples share most of their error), and the horizontal RMSE.
void Score(const test::DriveRun& run, const std::vector<StateEstimate>& est, double* nees, double* rmse_h) {
  double sum = 0.0, sum_h2 = 0.0, last = -1e9;
  int n = 0, m = 0;
  size_t j = 0;
  for (const StateEstimate& e : est) {
    while (j < run.truth_t.size() && run.truth_t[j] < e.x.t - 1e-9) ++j;
    if (j == run.truth_t.size()) break;
    if (std::abs(run.truth_t[j] - e.x.t) > 1e-6 || e.x.t < run.init_t + 60.0) continue;
    const Vec3 dp = e.x.p_wb - run.truth[j].p_wb;
    sum_h2 += dp.head<2>().squaredNorm();
    ++m;
    if (e.x.t - last < 5.0) continue;
    last = e.x.t;
    sum += dp.cwiseQuotient(e.sigma_p).squaredNorm();
    ++n;
  }
  *nees = n > 0 ? sum / n : 0.0;
  *rmse_h = m > 0 ? std::sqrt(sum_h2 / m) : 0.0;
}

Nees RunWith(const SimOptions& sim, double error_correlation) {
  Options o = test::TestRunOptions(sim);
  o.sensors.imu.gyro_noise_density = sim.gyro_noise_density;
  o.sensors.imu.acc_noise_density = sim.acc_noise_density;
  o.sensors.imu.gyro_bias_rw = sim.gyro_bias_rw;
  o.sensors.imu.acc_bias_rw = sim.acc_bias_rw;
  o.sensors.gnss.use_heading = false;
  o.sensors.gnss.min_sigma = 0.3;
  o.sensors.gnss.error_correlation = error_correlation;
  const test::DriveRun run = test::RunDriveThroughSession(sim, o);
  EXPECT_TRUE(run.initialized);
  Nees r;
  Score(run, run.eskf, &r.eskf, &r.rmse_h_eskf);
  Score(run, run.smoother, &r.smoother, &r.rmse_h_smoother);
  std::printf("error_correlation %.1f s: position NEES eskf %.2f, smoother %.2f (χ²(3): 3); rmse_h %.3f / %.3f m\n",
              error_correlation, r.eskf, r.smoother, r.rmse_h_eskf, r.rmse_h_smoother);
  return r;
}

TEST(CorrelatedGnss, NeesStaysHonestOnGaussMarkovSpp20Hz) {
  SimOptions sim = test::TestDrive(41);
  sim.gnss_rate = 20.0;
  sim.gnss_sigma_enu = Vec3(1.0, 1.0, 1.5);
  sim.gnss_noise_correlation = 1.0;  // s
  sim.heading_invalid_fraction = 1.0;
  sim.wheel_rate = 0.0;
  sim.gnss_outages.clear();
  const Nees honest = RunWith(sim, sim.gnss_noise_correlation);
  const Nees independent = RunWith(sim, 0.0);
  // About 25 samples of χ²(3) each, themselves correlated: a mean within [1, 6] is honest; treating the
  // fixes as independent is overconfident by far more.
  EXPECT_GT(honest.eskf, 1.0);
  EXPECT_LT(honest.eskf, 6.0);
  EXPECT_GT(honest.smoother, 1.0);
  EXPECT_LT(honest.smoother, 6.0);
  EXPECT_GT(independent.eskf, 3.0 * honest.eskf);
  EXPECT_GT(independent.smoother, 3.0 * honest.smoother);
}

}  // namespace
}  // namespace gins
