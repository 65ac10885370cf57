// What the estimators write before their initialisation (solver/pre_init_output.h): the rest states as they
// come and the fit's window at the initialisation (forward streams); the rest epochs and the window carried
// back from the first two-sided state (two-sided streams).
#include "solver/pre_init_output.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/so3.h"

namespace gins {
namespace {

const BridgeNoise kNoise{1e-4, 1e-3};

StateEstimate RestAt(double t) {
  StateEstimate s;
  s.x.t = t;
  s.sigma_p = Vec3(0.5, 0.5, 0.1);
  s.sigma_v = Vec3::Constant(0.01);
  s.sigma_att = Vec3(0.01, 0.01, kUnknownYawSigma);
  return s;
}

// A standstill [0, 10] s, then a fit's window from 10 s to 13 s.
InitResult StandstillThenFit() {
  InitResult init;
  init.start = "standstill";
  init.static_start = 0.0;
  init.static_end = 10.0;
  init.fit_start.t = 10.0;
  return init;
}

// The fit from 10 s (yaw 30°) to 13 s (yaw 50°, 12 m east and 4 m north on), without its IMU samples.
InitResult TurnedInit() {
  InitResult init = StandstillThenFit();
  init.fit_start.p_wb = Vec3(100.0, 200.0, 5.0);
  init.fit_start.q_wb = QuatFromYaw(30.0 * kDegToRad);
  init.x0.t = 13.0;
  init.x0.p_wb = Vec3(112.0, 204.0, 5.0);
  init.x0.v_w = Vec3(4.0, 1.0, 0.0);
  init.x0.q_wb = QuatFromYaw(50.0 * kDegToRad);
  return init;
}

// A standstill to 10 s, then 5 m/s east, level, on a flat Earth without rotation: the fit's window 10-13 s
// with its 100 Hz IMU samples (specific force: gravity's reaction alone).
InitResult StraightInit() {
  InitResult init = StandstillThenFit();
  init.fit_start.v_w = Vec3(5.0, 0.0, 0.0);
  init.x0 = init.fit_start;
  init.x0.t = 13.0;
  init.x0.p_wb = Vec3(15.0, 0.0, 0.0);
  init.fit_start_P = 0.01 * Mat15::Identity();
  init.P0 = 0.0001 * Mat15::Identity();
  for (int k = 0; k <= 300; ++k) {
    ImuSample s;
    s.t = 10.0 + 0.01 * k;
    s.acc = Vec3(0.0, 0.0, init.earth.g_norm());
    init.fit_imu.push_back(s);
  }
  return init;
}

TEST(PreInitOutput, ForwardStreamsGetEveryRestStateAsItComes) {
  PreInitOutput pre(kNoise);
  std::vector<double> a, b;
  const StateCallback fa = [&](const StateEstimate& s) { a.push_back(s.x.t); };
  const StateCallback fb = [&](const StateEstimate& s) { b.push_back(s.x.t); };
  for (double t : {1.0, 2.0, 3.0}) pre.Add(RestAt(t), false, fa, fb);
  EXPECT_EQ(a, (std::vector<double>{1.0, 2.0, 3.0}));
  EXPECT_EQ(b, a);
}

// At the initialisation the forward streams get the fit's window, bridged through its IMU samples, after
// the last rest state (the detector saw the start late) and before the fit's end (the estimator's own).
TEST(PreInitOutput, ForwardStreamsGetTheFitWindowAtTheInitialisation) {
  const InitResult init = StraightInit();
  PreInitOutput pre(kNoise);
  std::vector<StateEstimate> out;
  const StateCallback forward = [&](const StateEstimate& s) { out.push_back(s); };
  for (double t : {9.0, 9.5, 10.2}) pre.Add(RestAt(t), false, forward);
  pre.Start(init, forward);
  ASSERT_EQ(out.size(), 3u + 279u);  // 10.21 ... 12.99 s
  for (size_t i = 1; i < out.size(); ++i) EXPECT_GT(out[i].x.t, out[i - 1].x.t) << i;
  for (size_t i = 3; i < out.size(); ++i) {
    const double dt = out[i].x.t - 10.0;
    EXPECT_NEAR((out[i].x.p_wb - Vec3(5.0 * dt, 0.0, 0.0)).norm(), 0.0, 1e-9) << out[i].x.t;
    EXPECT_NEAR((out[i].x.v_w - Vec3(5.0, 0.0, 0.0)).norm(), 0.0, 1e-9);
    // σ between the ends' (0.1 and 0.01 m), nearer the later one as the window closes.
    EXPECT_LT(out[i].sigma_p.x(), 0.1 + 1e-9);
    EXPECT_GT(out[i].sigma_p.x(), 0.01);
  }
  EXPECT_NEAR(out[3].x.t, 10.21, 1e-9);
  EXPECT_NEAR(out.back().x.t, 12.99, 1e-9);
  // A watchdog's re-initialisation later writes nothing.
  InitResult again = init;
  again.fit_start.t = 20.0;
  again.x0.t = 23.0;
  pre.Start(again, forward);
  EXPECT_EQ(out.size(), 282u);
}

// The two-sided pass moved the fit's end 0.3 m and turned it 2°: the rest epochs get the attitude at rest
// this implies and the position the fit's displacement, turned with it, leads back to, with the first
// state's σ and the rest's zero velocity.
TEST(PreInitOutput, TwoSidedStreamCarriesItsFirstStateBackToTheStandstill) {
  const InitResult init = TurnedInit();
  PreInitOutput pre(kNoise);
  for (double t : {-1.0, 4.0, 9.0, 10.0, 11.0}) pre.Add(RestAt(t), true, nullptr);
  pre.Start(init, nullptr);
  StateEstimate first;
  first.x = init.x0;
  first.x.p_wb += Vec3(0.3, 0.0, 0.0);
  first.x.q_wb = QuatFromYaw(52.0 * kDegToRad);
  first.sigma_p = Vec3(0.02, 0.02, 0.03);
  first.sigma_att = Vec3(0.001, 0.001, 0.004);
  std::vector<StateEstimate> out;
  const StateCallback two_sided = pre.TwoSided([&](const StateEstimate& s) { out.push_back(s); });
  two_sided(first);
  StateEstimate later = first;
  later.x.t = 13.01;
  two_sided(later);

  // -1 s is before the standstill; 10 and 11 s are not before the fit's start.
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out[0].x.t, 4.0);
  EXPECT_EQ(out[1].x.t, 9.0);
  EXPECT_EQ(out[2].x.t, 13.0);
  EXPECT_EQ(out[3].x.t, 13.01);
  const Vec3 d = QuatFromYaw(2.0 * kDegToRad) * Vec3(12.0, 4.0, 0.0);
  for (int i = 0; i < 2; ++i) {
    const StateEstimate& s = out[static_cast<size_t>(i)];
    EXPECT_NEAR(YawOfXAxis<double>(s.x.R_wb()) * kRadToDeg, 32.0, 1e-9);
    EXPECT_NEAR((s.x.p_wb - (first.x.p_wb - d)).norm(), 0.0, 1e-9);
    EXPECT_EQ(s.x.v_w, Vec3::Zero());
    EXPECT_EQ(s.sigma_v, Vec3::Constant(0.01));
    EXPECT_EQ(s.sigma_att, first.sigma_att);
    EXPECT_EQ(s.sigma_p, first.sigma_p);
  }
}

// With the fit's IMU samples, the two-sided stream gets the rest epochs, then the window bridged from the
// carried start to its first state, then that state: every IMU epoch once, in time order.
TEST(PreInitOutput, TwoSidedStreamBridgesTheFitWindow) {
  const InitResult init = StraightInit();
  PreInitOutput pre(kNoise);
  for (double t : {8.0, 9.0, 9.99, 10.5}) pre.Add(RestAt(t), true, nullptr);
  pre.Start(init, nullptr);
  StateEstimate first;
  first.x = init.x0;
  first.x.p_wb.y() += 0.1;  // the two-sided pass moved the end north
  std::vector<StateEstimate> out;
  pre.TwoSided([&](const StateEstimate& s) { out.push_back(s); })(first);
  ASSERT_EQ(out.size(), 3u + 300u + 1u);  // 8, 9, 9.99; 10.00 ... 12.99; 13
  for (size_t i = 1; i < out.size(); ++i) EXPECT_GT(out[i].x.t, out[i - 1].x.t) << i;
  for (const StateEstimate& s : out) {
    EXPECT_NEAR(s.x.p_wb.y(), 0.1, 1e-9) << s.x.t;  // carried back with it
    const double dt = std::max(0.0, s.x.t - 10.0);
    EXPECT_NEAR(s.x.p_wb.x(), 5.0 * dt, 1e-9) << s.x.t;
  }
}

// A two-sided stream that does not start at the initialisation gets nothing in front, nor (no standstill)
// does an initialisation in motion get rest epochs.
TEST(PreInitOutput, NothingInFrontWhereTheFitDoesNotLeadToTheFirstState) {
  for (bool moving : {false, true}) {
    InitResult init = TurnedInit();
    if (moving) init.start = "moving";
    PreInitOutput pre(kNoise);
    pre.Add(RestAt(5.0), true, nullptr);
    pre.Start(init, nullptr);
    std::vector<double> out;
    const StateCallback two_sided = pre.TwoSided([&](const StateEstimate& s) { out.push_back(s.x.t); });
    StateEstimate first;
    first.x = init.x0;
    if (!moving) first.x.t = 14.0;
    two_sided(first);
    EXPECT_EQ(out, (std::vector<double>{first.x.t})) << moving;
  }
}

}  // namespace
}  // namespace gins
