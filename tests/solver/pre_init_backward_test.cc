// The backward run before the initialisation (solver/pre_init_backward.h), on seeded simulated drives with
// the Earth's rotation: the time-reversed mechanisation retraces the truth, and with noisy sensors its
// smoothed states, pinned by the fixes and the standstills, cover the truth within their σ.
#include "solver/pre_init_backward.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/sim/simulator.h"
#include "core/so3.h"
#include "test_scenarios.h"

namespace gins {
namespace GINS_TEST_FILE {

struct Drive {
  std::vector<ImuSample> imu;
  std::vector<NavState> truth;  // at each IMU sample
  EarthModel earth;
};

// The drive's IMU samples up to t_end (absolute), with a known gyro bias added to every sample (the truth
// states carry it).
Drive Simulate(const SimOptions& sim, double t_end, const Vec3& extra_bg) {
  Drive d;
  Simulator simulator(sim);
  d.earth = EarthModel::Rotating(simulator.truth().frame());
  SimRecord r;
  while (simulator.Next(&r) && r.t() <= t_end) {
    if (!r.is<ImuSample>()) continue;
    ImuSample s = r.get<ImuSample>();
    s.gyro += extra_bg;
    d.imu.push_back(s);
    NavState x = r.truth;
    x.bg += extra_bg;
    d.truth.push_back(x);
  }
  return d;
}

// The antenna's fix at truth state x: position with white noise of σ sigma.
GnssMeasurement FixAt(const NavState& x, const Vec3& lever_b, const Vec3& sigma, std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  GnssMeasurement f;
  f.t = x.t;
  f.p_w = x.p_wb + x.R_wb() * lever_b + Vec3(n(*rng), n(*rng), n(*rng)).cwiseProduct(sigma);
  f.sigma_w = sigma;
  return f;
}

StateEstimate EstimateAt(const NavState& x, double sigma_p, double sigma_v, double sigma_att) {
  StateEstimate s;
  s.x = x;
  s.sigma_p = Vec3::Constant(sigma_p);
  s.sigma_v = Vec3::Constant(sigma_v);
  s.sigma_att = Vec3::Constant(sigma_att);
  return s;
}

Mat15 CovarianceAt(double sigma_p, double sigma_v, double sigma_att, double sigma_bg, double sigma_ba) {
  Mat15 P = Mat15::Zero();
  const double s[] = {sigma_p, sigma_v, sigma_att, sigma_bg, sigma_ba};
  for (int b = 0; b < 5; ++b) P.block<3, 3>(3 * b, 3 * b).diagonal().setConstant(s[b] * s[b]);
  return P;
}

// Noise-free sensors and a known gyro bias of 0.1 deg/s: run backwards 40 s through acceleration, a 90°
// turn and a hill from the true state, the states retrace the truth. A wrong sign of the reversed
// velocity, gyro bias or Earth rate is metres off here (the Earth rate alone tilts the platform ~0.2° in
// 40 s: ~25 m).
TEST(FillBackward, TheReversedMechanisationRetracesTheTruth) {
  SimOptions sim = test::TestDrive(41);
  sim.gyro_noise_density = sim.acc_noise_density = 0.0;
  sim.gyro_bias_rw = sim.acc_bias_rw = 0.0;
  sim.gyro_turn_on_bias = sim.acc_turn_on_bias = 0.0;
  const double t0 = sim.start_time + 20.0, t_s = sim.start_time + 60.0;
  const Drive d = Simulate(sim, t_s, Vec3(0.1, -0.05, 0.08) * kDegToRad);
  BackwardSpan span;
  span.earth = d.earth;
  size_t i_s = 0;
  for (size_t i = 0; i < d.imu.size(); ++i) {
    if (d.imu[i].t < t0 - 1e-9) continue;
    if (d.imu[i].t >= t_s - 1e-9) {
      i_s = i;
      break;
    }
    span.imu.push_back(d.imu[i]);
  }
  ASSERT_GT(i_s, 0u);
  span.start = EstimateAt(d.truth[i_s], 1e-4, 1e-4, 1e-6);
  span.P = CovarianceAt(1e-4, 1e-4, 1e-6, 1e-9, 1e-6);
  std::mt19937 rng(1);
  span.fixes.push_back(FixAt(d.truth[i_s - 4000], Vec3::Zero(), Vec3::Constant(1e3), &rng));  // σ 1 km: says nothing
  span.from = t0;
  Options options = test::TestRunOptions(sim);
  const std::vector<StateEstimate> out = FillBackward(options.sensors, options.eskf, options.standstill, span);
  ASSERT_GT(out.size(), 3900u);
  EXPECT_NEAR(out.front().x.t, t0, 1e-6);
  EXPECT_LT(out.back().x.t, t_s);
  double max_p = 0.0, max_v = 0.0, max_att = 0.0;
  size_t j = 0, compared = 0;
  for (const StateEstimate& s : out) {
    while (j < d.truth.size() && d.truth[j].t < s.x.t - 1e-7) ++j;
    ASSERT_LT(j, d.truth.size());
    if (std::abs(d.truth[j].t - s.x.t) > 1e-7) continue;
    ++compared;
    max_p = std::max(max_p, (s.x.p_wb - d.truth[j].p_wb).norm());
    max_v = std::max(max_v, (s.x.v_w - d.truth[j].v_w).norm());
    max_att = std::max(max_att, LogQuat<double>(d.truth[j].q_wb.conjugate() * s.x.q_wb).norm());
  }
  std::printf("retraced 40 s: max position %.4f m, velocity %.4f m/s, attitude %.5f deg over %zu states\n", max_p,
              max_v, max_att * kRadToDeg, compared);
  EXPECT_GT(compared, 3900u);
  EXPECT_LT(max_p, 0.05);      // measured 0.005 m
  EXPECT_LT(max_v, 0.005);     // measured 0.0005 m/s
  EXPECT_LT(max_att * kRadToDeg, 0.005);
}

// A low-cost IMU (the test drive's), 1 Hz RTK fixes and the drive's 20 s standstill, from a start state
// 40 s into the drive known to 2 cm and 0.05°: every state from the first fix on, at rest with a velocity
// that the standstill updates hold at zero, within 3 σ of the truth (95 % of them) and a few cm off.
TEST(FillBackward, FixesAndStandstillsPinTheStatesBeforeTheStart) {
  const SimOptions sim = test::TestDrive(42);
  const double t_s = sim.start_time + 40.0;
  const Drive d = Simulate(sim, t_s, Vec3::Zero());
  const Options options = test::TestRunOptions(sim);
  BackwardSpan span;
  span.earth = d.earth;
  size_t i_s = 0;
  std::mt19937 rng(2);
  for (size_t i = 0; i < d.imu.size(); ++i) {
    if (d.imu[i].t >= t_s - 1e-9) {
      i_s = i;
      break;
    }
    span.imu.push_back(d.imu[i]);
    if (i % 100 == 50) span.fixes.push_back(FixAt(d.truth[i], options.sensors.gnss.lever_b, sim.gnss_sigma_enu, &rng));
  }
  ASSERT_GT(i_s, 0u);
  span.rests.push_back({sim.start_time, sim.start_time + 19.5});
  span.from = span.fixes.front().t;
  span.start = EstimateAt(d.truth[i_s], 0.02, 0.01, 0.05 * kDegToRad);
  const ImuOptions& imu = options.sensors.imu;
  span.P = CovarianceAt(0.02, 0.01, 0.05 * kDegToRad, imu.init_gyro_bias_sigma, imu.init_acc_bias_sigma);
  const std::vector<StateEstimate> out = FillBackward(options.sensors, options.eskf, options.standstill, span);
  ASSERT_FALSE(out.empty());
  EXPECT_NEAR(out.front().x.t, span.from, 1e-6);
  size_t n = 0, within = 0;
  double max_h = 0.0, max_rest_speed = 0.0;
  size_t j = 0;
  for (size_t k = 0; k < out.size(); ++k) {
    const StateEstimate& s = out[k];
    if (k > 0) {
      ASSERT_GT(s.x.t, out[k - 1].x.t);
    }
    while (j < d.truth.size() && d.truth[j].t < s.x.t - 1e-7) ++j;
    if (j == d.truth.size() || std::abs(d.truth[j].t - s.x.t) > 1e-7) continue;
    const Vec3 e = s.x.p_wb - d.truth[j].p_wb;
    ++n;
    within += (e.cwiseAbs().array() <= 3.0 * s.sigma_p.array()).all();
    max_h = std::max(max_h, e.head<2>().norm());
    if (s.x.t < sim.start_time + 19.5) max_rest_speed = std::max(max_rest_speed, s.x.v_w.norm());
  }
  std::printf("%zu states: %zu within 3 sigma, max horizontal %.3f m, max speed at rest %.4f m/s\n", n, within, max_h,
              max_rest_speed);
  EXPECT_GT(n, 3800u);
  EXPECT_GE(within, 0.95 * static_cast<double>(n));
  EXPECT_LT(max_h, 0.10);
  EXPECT_LT(max_rest_speed, 0.02);
}

// Nothing to fill: no fix before the start, or the span's fixes all at or after it.
TEST(FillBackward, NothingWithoutAFixBeforeTheStart) {
  BackwardSpan span;
  span.start.x.t = 10.0;
  span.imu.push_back(ImuSample{9.0, Vec3::Zero(), Vec3(0.0, 0.0, kStandardGravity)});
  EXPECT_TRUE(FillBackward(SensorOptions(), EskfOptions(), StandstillOptions(), span).empty());
  GnssMeasurement f;
  f.t = 10.0;
  span.fixes.push_back(f);
  EXPECT_TRUE(FillBackward(SensorOptions(), EskfOptions(), StandstillOptions(), span).empty());
}

}  // namespace
}  // namespace gins
