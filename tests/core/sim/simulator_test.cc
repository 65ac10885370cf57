#include "core/sim/simulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/gnss_model.h"
#include "core/heading_model.h"
#include "core/imu_kernel.h"
#include "core/so3.h"
#include "core/wheel_model.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

// 60 s: standstill, accelerate, climbing left turn, level right turn, descending left turn while braking,
// accelerate, brake hard enough to stop (the speed clamp engages for the last ~3 s).
// The flat Earth: these tests check its exact truth against the flat kernel and geodesy (the rotating Earth
// has its own in simulator_earth_test.cc).
SimOptions Drive() {
  SimOptions sim;
  sim.earth_rotation = false;
  sim.seed = 7;
  sim.initial_yaw = 0.3;
  sim.segments = {{2.0, 0.0, 0.0, 0.0},          {6.0, 1.5, 0.0, 0.0},
                  {10.0, 0.0, 0.15, 4 * kDegToRad}, {8.0, 0.2, -0.2, 0.0},
                  {10.0, -0.5, 0.1, -3 * kDegToRad}, {14.0, 0.3, 0.0, 0.0},
                  {10.0, -1.5, 0.0, 0.0}};
  return sim;
}

SimOptions NoiseFree(SimOptions sim) {
  sim.gyro_noise_density = sim.acc_noise_density = 0.0;
  sim.gyro_bias_rw = sim.acc_bias_rw = 0.0;
  sim.gyro_turn_on_bias = sim.acc_turn_on_bias = 0.0;
  sim.gnss_sigma_enu.setZero();
  sim.heading_sigma = 0.0;
  sim.heading_invalid_fraction = 0.0;
  sim.gnss_outlier_probability = 0.0;
  sim.wheel_speed_noise = 0.0;
  return sim;
}

std::vector<SimRecord> RunAll(const SimOptions& options) {
  Simulator sim(options);
  std::vector<SimRecord> out;
  SimRecord r;
  while (sim.Next(&r)) out.push_back(r);
  return out;
}

template <typename R>
std::vector<SimRecord> OfType(const std::vector<SimRecord>& all) {
  std::vector<SimRecord> out;
  std::copy_if(all.begin(), all.end(), std::back_inserter(out), [](const SimRecord& r) { return r.is<R>(); });
  return out;
}

double Pitch(const Quat& q_wb) {
  const Vec3 x_w = q_wb * Vec3::UnitX();
  return std::asin(x_w.z());
}

// ---------------------------------------------------------------------------------------------------------
// Truth

TEST(SimTruth, StartsAtRestAndFollowsSegments) {
  const TruthTrajectory truth(Drive());
  EXPECT_DOUBLE_EQ(truth.duration(), 60.0);
  const TruthState x0 = truth.AtElapsed(0.0);
  EXPECT_EQ(x0.p_wb, Vec3::Zero());
  EXPECT_EQ(x0.v_w, Vec3::Zero());
  EXPECT_NEAR(YawOfXAxis<double>(x0.q_wb.toRotationMatrix()), 0.3, 1e-15);
  EXPECT_NEAR(std::abs(truth.gravity_w().z() + NormalGravity(31.5, 10.0)), 0.0, 1e-12);
  // Standstill segment: nothing moves.
  EXPECT_EQ(truth.AtElapsed(2.0).p_wb, Vec3::Zero());
  // Accelerating 1.5 m/s² after a 1 s ramp: 0.75 + 1.5·5 m/s at 8 s.
  EXPECT_NEAR(truth.AtElapsed(8.0).speed, 8.25, 1e-12);
  // Grade reached at the end of its segment, yaw rate after the 1 s ramp.
  EXPECT_NEAR(Pitch(truth.AtElapsed(18.0).q_wb), 4 * kDegToRad, 1e-12);
  EXPECT_NEAR(truth.AtElapsed(12.0).omega_b.z(), 0.15 * std::cos(Pitch(truth.AtElapsed(12.0).q_wb)), 1e-12);
  EXPECT_GT(truth.AtElapsed(18.0).p_wb.z(), 1.0);  // climbed the hill
}

TEST(SimTruth, SpeedClampsAtZeroAndRestarts) {
  SimOptions sim = Drive();
  sim.segments.push_back({5.0, 1.0, 0.0, 0.0});  // drive off again
  const TruthTrajectory truth(sim);
  double min_speed = 1e9;
  for (double s = 0.0; s <= truth.duration(); s += 0.01) min_speed = std::min(min_speed, truth.AtElapsed(s).speed);
  EXPECT_GE(min_speed, 0.0);
  // Speed at 50 s ≈ 9.15 m/s; braking at −1.5 m/s² stops it by ~57 s and it stays stopped to 60 s.
  const TruthState a = truth.AtElapsed(58.0), b = truth.AtElapsed(60.0);
  EXPECT_EQ(a.speed, 0.0);
  EXPECT_EQ(a.a_w, Vec3::Zero());
  EXPECT_EQ(a.p_wb, b.p_wb);
  // The new segment's acceleration turns positive half-way through its ramp, and the car moves off.
  EXPECT_GT(truth.AtElapsed(61.0).speed, 0.0);
  EXPECT_NEAR(truth.AtElapsed(65.0).speed, 0.5 * 0.5 * 1.0 * 0.5 + 4.0, 0.2);
}

// p, v, q and the reported v, a_w, ω_b agree by central differences: the truth is self-consistent, so
// the IMU (built from ω_b, a_w) and the truth (p, v, q) describe one motion.
TEST(SimTruth, DerivativesConsistent) {
  const TruthTrajectory truth(Drive());
  const double h = 1e-4;
  int checked = 0;
  for (double s = 0.013; s < truth.duration() - h; s += 0.37) {
    const TruthState m = truth.AtElapsed(s - h), x = truth.AtElapsed(s), p = truth.AtElapsed(s + h);
    if (m.speed == 0.0 || p.speed == 0.0) continue;  // the stop is the one kink in a_w
    EXPECT_LT(((p.p_wb - m.p_wb) / (2 * h) - x.v_w).norm(), 1e-7) << s;
    EXPECT_LT(((p.v_w - m.v_w) / (2 * h) - x.a_w).norm(), 1e-6) << s;
    EXPECT_LT((LogQuat<double>(m.q_wb.conjugate() * p.q_wb) / (2 * h) - x.omega_b).norm(), 1e-7) << s;
    // No side slip: the velocity is along the body x axis.
    EXPECT_LT((x.q_wb.conjugate() * x.v_w).tail<2>().norm(), 1e-12) << s;
    ++checked;
  }
  EXPECT_GT(checked, 130);
}

// With the rear axle 1.5 m behind the IMU (simulate.wheel_lever_arm_m): the segments drive the axle, which
// does not slip; the IMU, a rigid point ahead of it, slides sideways in turns by ω·1.5 m, and its p, v, a_w
// stay consistent by central differences.
TEST(SimTruth, AxleLeverPutsTheImuAheadOfTheNonSlippingAxle) {
  SimOptions sim = Drive();
  sim.wheel_lever_b = Vec3(-1.5, 0.2, -0.3);
  const TruthTrajectory truth(sim), on_axle(Drive());
  const double h = 1e-4;
  int checked = 0, sliding = 0;
  for (double s = 0.013; s < truth.duration() - h; s += 0.37) {
    const TruthState m = truth.AtElapsed(s - h), x = truth.AtElapsed(s), p = truth.AtElapsed(s + h);
    if (m.speed == 0.0 || p.speed == 0.0) continue;
    EXPECT_LT(((p.p_wb - m.p_wb) / (2 * h) - x.v_w).norm(), 1e-7) << s;
    EXPECT_LT(((p.v_w - m.v_w) / (2 * h) - x.a_w).norm(), 1e-5) << s;
    // The axle point: the path of the drive without the arm, and no side slip there.
    const TruthState a = on_axle.AtElapsed(s);
    EXPECT_LT((x.p_wb + x.q_wb * sim.wheel_lever_b - a.p_wb).norm(), 1e-9) << s;
    const Vec3 v_axle_b = x.q_wb.conjugate() * x.v_w + x.omega_b.cross(sim.wheel_lever_b);
    EXPECT_LT(v_axle_b.tail<2>().norm(), 1e-9) << s;
    // The IMU's own sideways speed: ω_z times the 1.5 m (and the small y arm's share).
    const Vec3 v_imu_b = x.q_wb.conjugate() * x.v_w;
    EXPECT_NEAR(v_imu_b.y(), x.omega_b.z() * 1.5 - x.omega_b.x() * 0.3, 1e-9) << s;
    sliding += std::abs(v_imu_b.y()) > 0.1;
    ++checked;
  }
  EXPECT_GT(checked, 130);
  EXPECT_GT(sliding, 30);  // the turns
}

// Random segments (short ones, sign changes, repeated stops and starts): the speed stays ≥ 0 and
// continuous, and p, v, q stay consistent with v, a_w, ω_b away from the stop kinks.
TEST(SimTruth, RandomSegmentsStayConsistent) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  SimOptions sim;
  for (int i = 0; i < 40; ++i) {
    sim.segments.push_back({i % 7 == 3 ? 0.0 : 0.2 + 6.0 * u(rng), -2.0 + 4.0 * u(rng), -0.3 + 0.6 * u(rng),
                            (-5.0 + 10.0 * u(rng)) * kDegToRad});
  }
  const TruthTrajectory truth(sim);
  int stopped = 0, checked = 0;
  double prev_speed = 0.0;
  for (double s = 0.0; s <= truth.duration(); s += 2e-3) {
    const double speed = truth.AtElapsed(s).speed;
    ASSERT_GE(speed, 0.0) << s;
    ASSERT_LT(std::abs(speed - prev_speed), 4.1e-3) << s;  // |a| ≤ 2 m/s²
    prev_speed = speed;
    stopped += speed == 0.0;
  }
  EXPECT_GT(stopped, 500);  // the clamp held the car for over a second
  const double h = 1e-5;
  for (double s = 0.0123; s < truth.duration() - h; s += 0.0731) {
    const TruthState m = truth.AtElapsed(s - h), x = truth.AtElapsed(s), p = truth.AtElapsed(s + h);
    EXPECT_NEAR(x.q_wb.norm(), 1.0, 1e-12);
    EXPECT_LT((LogQuat<double>(m.q_wb.conjugate() * p.q_wb) / (2 * h) - x.omega_b).norm(), 1e-6) << s;
    EXPECT_LT(((p.p_wb - m.p_wb) / (2 * h) - x.v_w).norm(), 1e-6) << s;
    if (m.speed == 0.0 && p.speed == 0.0) {
      EXPECT_EQ(p.p_wb, m.p_wb) << s;  // parked
    }
    if (m.speed == 0.0 || p.speed == 0.0) continue;
    EXPECT_LT(((p.v_w - m.v_w) / (2 * h) - x.a_w).norm(), 1e-4) << s;
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

// ---------------------------------------------------------------------------------------------------------
// IMU

struct KernelRun {
  double max_p = 0.0, max_v = 0.0, max_att = 0.0;  // largest errors against the truth
  std::vector<Vec3> p, v;                          // kernel states at the 100 Hz times (elapsed k/100)
};

// Integrates the simulator's noise-free IMU with gins's kernel from the true initial state.
KernelRun IntegrateWithKernel(double imu_rate) {
  SimOptions options = NoiseFree(Drive());
  options.imu_rate = imu_rate;
  options.gnss_rate = options.wheel_rate = 0.0;
  Simulator sim(options);
  SimRecord prev, r;
  EXPECT_TRUE(sim.Next(&prev));
  Kinematics k{prev.truth.q_wb, prev.truth.v_w, prev.truth.p_wb};
  KernelRun run;
  run.p.push_back(k.p);
  run.v.push_back(k.v);
  const int keep_every = static_cast<int>(imu_rate / 100.0);
  for (int i = 1; sim.Next(&r); ++i) {
    const ImuSample &a = prev.get<ImuSample>(), &b = r.get<ImuSample>();
    k = ImuStep(k, a.gyro, a.acc, sim.truth().gravity_w(), b.t - a.t);
    const NavState& x = r.truth;  // exact at the sample (record times carry unix-time round-off)
    run.max_p = std::max(run.max_p, (k.p - x.p_wb).norm());
    run.max_v = std::max(run.max_v, (k.v - x.v_w).norm());
    run.max_att = std::max(run.max_att, LogQuat<double>(x.q_wb.conjugate() * k.q).norm());
    if (i % keep_every == 0) {
      run.p.push_back(k.p);
      run.v.push_back(k.v);
    }
    prev = r;
  }
  return run;
}

// The kernel holds ω and a over each interval at the value sampled at its start (first order). On this
// drive that costs, at 100 Hz: 1.04 m, 3.4 cm/s and 1.0 mrad (= Δω·dt/2 for the 0.2 rad/s yaw-rate
// change: the attitude lags while turning, and the specific force is rotated by the lagged attitude).
// Two checks that this is the kernel's truncation error and not a mismatch between IMU and truth:
//  - halving dt halves every error (first order);
//  - the Richardson extrapolation 2·x(dt/2) − x(dt) cancels the first-order term and lands on the truth:
//    measured 0.14 mm and 0.023 mm/s (limits 1 mm, 0.1 mm/s), 4 and 3 orders below the 100 Hz error.
//    An IMU inconsistent with the truth would leave an error that neither shrinks with dt nor cancels.
TEST(SimImu, NoiseFreeImuThroughKernelFollowsTruth) {
  const KernelRun r100 = IntegrateWithKernel(100.0);
  const KernelRun r200 = IntegrateWithKernel(200.0);
  EXPECT_LT(r100.max_p, 1.5);
  EXPECT_LT(r100.max_v, 0.05);
  EXPECT_LT(r100.max_att, 1.5e-3);
  EXPECT_NEAR(r100.max_p / r200.max_p, 2.0, 0.2);
  EXPECT_NEAR(r100.max_v / r200.max_v, 2.0, 0.2);
  EXPECT_NEAR(r100.max_att / r200.max_att, 2.0, 0.2);

  // Up to 56.5 s: the car stops at ~57.0 s, where a_w steps by 1.5 m/s² inside one interval; a step's
  // O(dt) error depends on where in the interval it falls, so it does not cancel (measured 5 mm/s).
  const TruthTrajectory truth(NoiseFree(Drive()));
  ASSERT_EQ(r100.p.size(), 6001u);
  ASSERT_EQ(r200.p.size(), 6001u);
  double max_p = 0.0, max_v = 0.0;
  for (size_t i = 0; i <= 5650; ++i) {
    const TruthState x = truth.AtElapsed(static_cast<double>(i) / 100.0);
    max_p = std::max(max_p, (2.0 * r200.p[i] - r100.p[i] - x.p_wb).norm());
    max_v = std::max(max_v, (2.0 * r200.v[i] - r100.v[i] - x.v_w).norm());
  }
  EXPECT_GT(truth.AtElapsed(56.5).speed, 0.5);  // the window ends before the stop
  EXPECT_LT(max_p, 1e-3);
  EXPECT_LT(max_v, 1e-4);
  RecordProperty("kernel_100hz_max_p_m", std::to_string(r100.max_p));
  RecordProperty("richardson_max_p_m", std::to_string(max_p));
}

// Gyro − (ω + bg) and acc − (R_wbᵀ(a − g) + ba) are white with σ = density·√rate; biases walk.
TEST(SimImu, NoiseAndBiasStatistics) {
  SimOptions options = Drive();
  options.gnss_rate = options.wheel_rate = 0.0;
  options.gyro_bias_rw *= 100.0;  // make the walk visible over 60 s
  Simulator sim(options);
  SimRecord r;
  double sg = 0.0, sa = 0.0;
  int n = 0;
  Vec3 bg0 = Vec3::Zero();
  Vec3 bg_last = Vec3::Zero();
  while (sim.Next(&r)) {
    const TruthState x = sim.truth().At(r.get<ImuSample>().t);
    const Vec3 eg = r.get<ImuSample>().gyro - x.omega_b - r.truth.bg;
    const Vec3 ea = r.get<ImuSample>().acc - x.q_wb.conjugate() * (x.a_w - sim.truth().gravity_w()) - r.truth.ba;
    sg += eg.squaredNorm();
    sa += ea.squaredNorm();
    if (n == 0) bg0 = r.truth.bg;
    bg_last = r.truth.bg;
    ++n;
  }
  const double sigma_g = options.gyro_noise_density * std::sqrt(options.imu_rate);
  const double sigma_a = options.acc_noise_density * std::sqrt(options.imu_rate);
  EXPECT_NEAR(std::sqrt(sg / (3 * n)) / sigma_g, 1.0, 0.03);  // 18000 draws: ±0.5 % 1-σ
  EXPECT_NEAR(std::sqrt(sa / (3 * n)) / sigma_a, 1.0, 0.03);
  EXPECT_GT(bg0.norm(), 0.0);  // turn-on bias present
  EXPECT_GT((bg_last - bg0).norm(), 0.1 * options.gyro_bias_rw * std::sqrt(60.0));
}

// ---------------------------------------------------------------------------------------------------------
// GNSS

TEST(SimGnss, NoiseFreeFixesHaveZeroResidualsAtTruth) {
  SimOptions options = NoiseFree(Drive());
  options.gnss_rate = 5.0;
  const std::vector<SimRecord> fixes = OfType<GnssRecord>(RunAll(options));
  ASSERT_EQ(fixes.size(), 301u);
  const LocalEnuFrame frame(options.origin);
  for (const SimRecord& r : fixes) {
    const GnssRecord& fix = r.get<GnssRecord>();
    const NavState& x = r.truth;
    const Vec3 z_w = frame.ToEnu({fix.lat_deg, fix.lon_deg, fix.alt_m});
    EXPECT_LT(GnssPositionModel::Residual<double>(x.p_wb, x.q_wb, options.lever_b, z_w).norm(), 1e-8);
    ASSERT_TRUE(fix.heading_valid);
    EXPECT_NEAR(HeadingModel::Residual<double>(x.q_wb, options.mount_yaw, CompassDegToEnuYaw(fix.heading_deg)),
                0.0, 1e-10);
    EXPECT_TRUE(fix.has_sigma);
    EXPECT_EQ(fix.sigma_enu, options.gnss_sigma_enu);
  }
}

TEST(SimGnss, NoiseMatchesSigma) {
  SimOptions options = Drive();
  options.gnss_rate = 20.0;
  options.wheel_rate = 0.0;
  options.imu_rate = 1.0;  // keep the test fast; the IMU plays no part
  const std::vector<SimRecord> fixes = OfType<GnssRecord>(RunAll(options));
  const LocalEnuFrame frame(options.origin);
  Vec3 sum_sq = Vec3::Zero();
  double sum_sq_yaw = 0.0;
  int n_yaw = 0;
  for (const SimRecord& r : fixes) {
    const GnssRecord& fix = r.get<GnssRecord>();
    const NavState& x = r.truth;
    const Vec3 z_w = frame.ToEnu({fix.lat_deg, fix.lon_deg, fix.alt_m});
    sum_sq += GnssPositionModel::Residual<double>(x.p_wb, x.q_wb, options.lever_b, z_w).cwiseAbs2();
    if (fix.heading_valid) {
      sum_sq_yaw += std::pow(
          HeadingModel::Residual<double>(x.q_wb, options.mount_yaw, CompassDegToEnuYaw(fix.heading_deg)), 2);
      ++n_yaw;
    }
  }
  const Vec3 rms = (sum_sq / fixes.size()).cwiseSqrt();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(rms[i] / options.gnss_sigma_enu[i], 1.0, 0.1);  // 1201 fixes
  EXPECT_NEAR(std::sqrt(sum_sq_yaw / n_yaw) / options.heading_sigma, 1.0, 0.1);
  // Heading invalid at the configured 5 %: 1201 fixes, 1-σ ≈ 7.5.
  EXPECT_NEAR(static_cast<double>(fixes.size() - n_yaw), 0.05 * fixes.size(), 30.0);
}

TEST(SimGnss, OutagesHaveNoFixes) {
  SimOptions options = NoiseFree(Drive());
  options.gnss_rate = 10.0;
  options.gnss_outages = {{10.0, 5.0}, {30.05, 2.5}};
  const std::vector<SimRecord> fixes = OfType<GnssRecord>(RunAll(options));
  EXPECT_EQ(fixes.size(), 601u - 50u - 25u);
  bool seen_15 = false;
  for (const SimRecord& r : fixes) {
    const double s = r.get<GnssRecord>().t - options.start_time;
    EXPECT_FALSE(s > 10.0 - 1e-4 && s < 15.0 - 1e-4) << s;
    EXPECT_FALSE(s > 30.05 - 1e-4 && s < 32.55 - 1e-4) << s;
    seen_15 |= std::abs(s - 15.0) < 1e-4;  // the window is half open
  }
  EXPECT_TRUE(seen_15);
}

TEST(SimGnss, OutliersAtConfiguredRateAndMagnitude) {
  SimOptions options = NoiseFree(Drive());
  options.gnss_rate = 50.0;
  options.imu_rate = 1.0;
  options.wheel_rate = 0.0;
  options.gnss_outlier_probability = 0.1;
  options.gnss_outlier_magnitude = 20.0;
  const std::vector<SimRecord> fixes = OfType<GnssRecord>(RunAll(options));
  const LocalEnuFrame frame(options.origin);
  int outliers = 0;
  for (const SimRecord& r : fixes) {
    const GnssRecord& fix = r.get<GnssRecord>();
    const NavState& x = r.truth;
    const Vec3 z_w = frame.ToEnu({fix.lat_deg, fix.lon_deg, fix.alt_m});
    const Vec3 res = GnssPositionModel::Residual<double>(x.p_wb, x.q_wb, options.lever_b, z_w);
    const bool is_outlier = res.norm() > 1.0;
    EXPECT_EQ(is_outlier, r.gnss_outlier);
    if (is_outlier) {
      EXPECT_NEAR(res.head<2>().norm(), 20.0, 1e-8);
      EXPECT_NEAR(res.z(), 0.0, 1e-8);
      ++outliers;
    }
  }
  // 3001 fixes at p = 0.1: mean 300, 1-σ ≈ 16.
  EXPECT_NEAR(outliers, 0.1 * fixes.size(), 60.0);
}

// ---------------------------------------------------------------------------------------------------------
// Wheels

TEST(SimWheel, PulsesGiveTruthSpeedWithinQuantisation) {
  SimOptions options = NoiseFree(Drive());
  const std::vector<SimRecord> wheel = OfType<WheelRecord>(RunAll(options));
  ASSERT_EQ(wheel.size(), 600u);
  const TruthTrajectory truth(options);
  const double dt = 1.0 / options.wheel_rate;
  // One pulse (the most the carried remainder can shift a count) as a speed.
  const double pulse_speed = WheelSpeedFromPulses(1.0, options.wheel_radius, options.pulses_per_rev, dt);
  double max_err = 0.0;
  for (const SimRecord& r : wheel) {
    const WheelRecord& wheel_record = r.get<WheelRecord>();
    const double left = WheelSpeedFromPulses(wheel_record.left_pulses, options.wheel_radius, options.pulses_per_rev, dt);
    const double right = WheelSpeedFromPulses(wheel_record.right_pulses, options.wheel_radius, options.pulses_per_rev, dt);
    EXPECT_EQ(wheel_record.left_pulses, std::round(wheel_record.left_pulses));
    const double s1 = wheel_record.t - options.start_time;
    // The counts measure the mean speed over (t − Δt, t].
    const Vec2 mean = truth.IntegrateSpeedAndYawRate(s1 - dt, s1) / dt;
    max_err = std::max(max_err, std::abs(0.5 * (left + right) / options.wheel_scale - mean.x()));
    // While turning, the outer (right, for a left turn) wheel runs faster by ω_z·track.
    EXPECT_NEAR((right - left) / options.wheel_scale, mean.y() * options.track_width, 2 * pulse_speed + 1e-9);
  }
  EXPECT_LT(max_err, pulse_speed / options.wheel_scale + 1e-9);
  EXPECT_GT(max_err, 0.0);
}

// Parked (the first 2 s and the last ~3 s of the drive), noisy encoders still count nothing; rolling,
// the noise shows.
TEST(SimWheel, ParkedWheelsCountNothing) {
  const SimOptions options = Drive();
  const std::vector<SimRecord> wheel = OfType<WheelRecord>(RunAll(options));
  const TruthTrajectory truth(options);
  const double dt = 1.0 / options.wheel_rate;
  int parked = 0, rolling = 0;
  double sum_sq = 0.0;
  for (const SimRecord& r : wheel) {
    const WheelRecord& wheel_record = r.get<WheelRecord>();
    const double s1 = wheel_record.t - options.start_time;
    const double distance = truth.IntegrateSpeedAndYawRate(s1 - dt, s1).x();
    if (distance == 0.0) {
      EXPECT_EQ(wheel_record.left_pulses, 0.0);
      EXPECT_EQ(wheel_record.right_pulses, 0.0);
      ++parked;
    } else if (distance > 0.1) {
      const double v = WheelSpeedFromPulses(0.5 * (wheel_record.left_pulses + wheel_record.right_pulses), options.wheel_radius,
                                            options.pulses_per_rev, dt);
      sum_sq += std::pow(v - options.wheel_scale * distance / dt, 2);
      ++rolling;
    }
  }
  EXPECT_GT(parked, 40);
  EXPECT_GT(rolling, 500);
  // Mean of two wheels: 0.02/√2 = 0.0141 m/s of noise; the carried quantisation (a difference of two
  // remainders, 1/6 pulse² per wheel) adds 0.0027 m/s: 0.0144 in all. ~550 intervals: ±3 % 1-σ.
  EXPECT_NEAR(std::sqrt(sum_sq / rolling), 0.0144, 0.0015);
}

// ---------------------------------------------------------------------------------------------------------
// Stream, seeds, options

TEST(SimStream, TimeOrderedWithExpectedCounts) {
  const std::vector<SimRecord> all = RunAll(Drive());
  EXPECT_EQ(OfType<ImuSample>(all).size(), 6001u);
  EXPECT_EQ(OfType<GnssRecord>(all).size(), 61u);
  EXPECT_EQ(OfType<WheelRecord>(all).size(), 600u);
  for (size_t i = 1; i < all.size(); ++i) {
    ASSERT_LE(all[i - 1].t(), all[i].t());
    // Ties: the IMU sample comes first, so a filter has propagated to t before it updates at t.
    if (all[i - 1].t() == all[i].t()) {
      EXPECT_FALSE(all[i].is<ImuSample>());
    }
  }
  EXPECT_DOUBLE_EQ(all.front().t(), Drive().start_time);
  EXPECT_DOUBLE_EQ(all.back().t(), Drive().start_time + 60.0);
}

bool SameImu(const ImuSample& a, const ImuSample& b) { return a.t == b.t && a.gyro == b.gyro && a.acc == b.acc; }

TEST(SimRandom, ReproducibleFromSeed) {
  const std::vector<SimRecord> a = RunAll(Drive()), b = RunAll(Drive());
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].type_index(), b[i].type_index());
    EXPECT_EQ(a[i].t(), b[i].t());
    if (const ImuSample* imu = a[i].get_if<ImuSample>()) {
      EXPECT_TRUE(SameImu(*imu, b[i].get<ImuSample>()));
    }
    if (const WheelRecord* wheel = a[i].get_if<WheelRecord>()) {
      EXPECT_EQ(wheel->left_pulses, b[i].get<WheelRecord>().left_pulses);
      EXPECT_EQ(wheel->right_pulses, b[i].get<WheelRecord>().right_pulses);
    }
    if (const GnssRecord* fix = a[i].get_if<GnssRecord>()) {
      EXPECT_EQ(fix->lat_deg, b[i].get<GnssRecord>().lat_deg);
      EXPECT_EQ(fix->heading_deg, b[i].get<GnssRecord>().heading_deg);
    }
  }
  SimOptions other = Drive();
  other.seed = 8;
  const std::vector<SimRecord> c = RunAll(other);
  ASSERT_EQ(a.size(), c.size());
  int imu_differ = 0, gnss_differ = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    imu_differ += a[i].is<ImuSample>() && !SameImu(a[i].get<ImuSample>(), c[i].get<ImuSample>());
    gnss_differ += a[i].is<GnssRecord>() && a[i].get<GnssRecord>().lat_deg != c[i].get<GnssRecord>().lat_deg;
  }
  EXPECT_EQ(imu_differ, 6001);
  EXPECT_EQ(gnss_differ, 61);
}

// Each source has its own engine and a fixed number of draws per sample: other sensors' settings do not
// change a sensor's noise.
TEST(SimRandom, SensorStreamsIndependent) {
  SimOptions base = Drive();
  base.gnss_rate = 5.0;
  SimOptions changed = base;
  changed.gnss_outlier_probability = 0.3;
  changed.heading_invalid_fraction = 0.5;
  changed.gnss_outages = {{20.0, 10.0}};
  changed.wheel_rate = 0.0;
  const std::vector<SimRecord> a = RunAll(base), b = RunAll(changed);
  const auto imu_a = OfType<ImuSample>(a), imu_b = OfType<ImuSample>(b);
  ASSERT_EQ(imu_a.size(), imu_b.size());
  for (size_t i = 0; i < imu_a.size(); ++i) {
    ASSERT_TRUE(SameImu(imu_a[i].get<ImuSample>(), imu_b[i].get<ImuSample>())) << i;
  }
  // Fixes that are not outliers in either run are identical.
  const auto gnss_a = OfType<GnssRecord>(a), gnss_b = OfType<GnssRecord>(b);
  size_t j = 0, compared = 0;
  for (const SimRecord& r : gnss_b) {
    const GnssRecord& fix = r.get<GnssRecord>();
    while (gnss_a[j].get<GnssRecord>().t < fix.t) ++j;
    if (r.gnss_outlier || gnss_a[j].gnss_outlier) continue;
    EXPECT_EQ(fix.lat_deg, gnss_a[j].get<GnssRecord>().lat_deg);
    EXPECT_EQ(fix.alt_m, gnss_a[j].get<GnssRecord>().alt_m);
    ++compared;
  }
  EXPECT_GT(compared, 100u);
}

TEST(SimOptionsCheck, RejectsInvalidOptions) {
  SimOptions sim = Drive();
  sim.segments.clear();
  EXPECT_THROW(Simulator{sim}, std::invalid_argument);
  sim = Drive();
  sim.segments[1].duration = -1.0;
  EXPECT_THROW(Simulator{sim}, std::invalid_argument);
  sim = Drive();
  sim.imu_rate = 0.0;
  EXPECT_THROW(Simulator{sim}, std::invalid_argument);
  sim = Drive();
  sim.gnss_outlier_probability = 1.5;
  EXPECT_THROW(Simulator{sim}, std::invalid_argument);
  sim = Drive();
  sim.gnss_rate = 0.0;  // GNSS off is valid
  EXPECT_TRUE(OfType<GnssRecord>(RunAll(sim)).empty());
}

// ---------------------------------------------------------------------------------------------------------
// Files

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> Fields(const std::string& line, char sep = ' ') {
  std::vector<std::string> f;
  std::istringstream in(line);
  for (std::string s; std::getline(in, s, sep);) {
    if (!s.empty()) f.push_back(s);
  }
  return f;
}

TEST(SimFiles, SimulateWritesParsableLogAndTruth) {
  SimOptions options = Drive();
  options.segments.resize(3);  // 18 s
  const std::string dir = test::MakeTempDir("sim") + "/out";  // created by Simulate
  const SimulationResult result = Simulate(options, dir);
  EXPECT_EQ(CountOf<ImuSample>(result.records), 1801u);
  EXPECT_EQ(CountOf<GnssRecord>(result.records), 19u);
  EXPECT_EQ(CountOf<WheelRecord>(result.records), 180u);
  EXPECT_DOUBLE_EQ(result.duration, 18.0);

  const std::vector<std::string> log = Lines(test::ReadFile(dir + "/log.txt"));
  ASSERT_EQ(log.size(), 2u + 1801u + 19u + 180u);
  EXPECT_EQ(log[0].rfind("# gins simulate seed=7 ", 0), 0u) << log[0];
  // Compare the text with the in-memory stream, record by record.
  const std::vector<SimRecord> records = RunAll(options);
  size_t n = 0;
  double last_t = 0.0;
  for (const std::string& line : log) {
    if (line[0] == '#') continue;
    const std::vector<std::string> f = Fields(line);
    const SimRecord& r = records.at(n++);
    const double t = std::stod(f.at(1));
    EXPECT_NEAR(t, r.t(), 1e-6);
    EXPECT_GE(t, last_t);
    last_t = t;
    if (f[0] == "IMU") {
      ASSERT_EQ(f.size(), 8u) << line;
      ASSERT_TRUE(r.is<ImuSample>());
      const ImuSample& imu = r.get<ImuSample>();
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(std::stod(f[2 + i]), imu.gyro[i], 1e-9 * std::abs(imu.gyro[i]) + 1e-300);
        EXPECT_NEAR(std::stod(f[5 + i]), imu.acc[i], 1e-9 * std::abs(imu.acc[i]) + 1e-300);
      }
    } else if (f[0] == "ODOM") {
      ASSERT_EQ(f.size(), 4u) << line;
      ASSERT_TRUE(r.is<WheelRecord>());
      EXPECT_EQ(std::stod(f[2]), r.get<WheelRecord>().left_pulses);
      EXPECT_EQ(std::stod(f[3]), r.get<WheelRecord>().right_pulses);
    } else {
      ASSERT_EQ(f[0], "GNSS");
      ASSERT_EQ(f.size(), 10u) << line;
      ASSERT_TRUE(r.is<GnssRecord>());
      EXPECT_NEAR(std::stod(f[2]), r.get<GnssRecord>().lat_deg, 1e-10);
      EXPECT_NEAR(std::stod(f[3]), r.get<GnssRecord>().lon_deg, 1e-10);
      EXPECT_NEAR(std::stod(f[4]), r.get<GnssRecord>().alt_m, 1e-4);
      EXPECT_EQ(f[6], r.get<GnssRecord>().heading_valid ? "1" : "0");
      EXPECT_NEAR(std::stod(f[9]), options.gnss_sigma_enu.z(), 1e-12);
    }
  }
  EXPECT_EQ(n, records.size());

  const std::vector<std::string> truth = Lines(test::ReadFile(dir + "/truth.csv"));
  ASSERT_EQ(truth.size(), 1u + 1801u);
  EXPECT_EQ(truth[0], "t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu");
  const TruthTrajectory traj(options);
  for (size_t i : {size_t{1}, size_t{900}, size_t{1801}}) {
    const std::vector<std::string> f = Fields(truth[i], ',');
    ASSERT_EQ(f.size(), 11u) << truth[i];
    const TruthState x = traj.At(std::stod(f[0]));
    const Vec3 p_w = traj.frame().ToEnu({std::stod(f[1]), std::stod(f[2]), std::stod(f[3])});
    EXPECT_LT((p_w - x.p_wb).norm(), 1e-3) << truth[i];
    const Quat q(std::stod(f[4]), std::stod(f[5]), std::stod(f[6]), std::stod(f[7]));
    EXPECT_LT(q.angularDistance(x.q_wb), 1e-6);
    EXPECT_LT((Vec3(std::stod(f[8]), std::stod(f[9]), std::stod(f[10])) - x.v_w).norm(), 1e-5);
  }
  // Only the two finished files: no temporaries left behind.
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 2);
}

TEST(SimFiles, WithoutSigmaColumns) {
  SimOptions options = Drive();
  options.segments.resize(2);
  options.write_gnss_sigma = false;
  const std::string dir = test::MakeTempDir("sim");
  Simulate(options, dir);
  int gnss = 0;
  for (const std::string& line : Lines(test::ReadFile(dir + "/log.txt"))) {
    if (line.rfind("GNSS", 0) != 0) continue;
    EXPECT_EQ(Fields(line).size(), 7u) << line;
    ++gnss;
  }
  EXPECT_EQ(gnss, 9);
}

TEST(SimFiles, ThrowsWhenTheDirectoryCannotBeUsed) {
  const std::string dir = test::MakeTempDir("sim");
  test::WriteFile(dir + "/file", "x");
  SimOptions options = Drive();
  options.segments.resize(2);
  EXPECT_THROW(Simulate(options, dir + "/file"), std::runtime_error);
  EXPECT_THROW(Simulate(options, dir + "/file/sub"), std::runtime_error);
}

}  // namespace
}  // namespace gins
