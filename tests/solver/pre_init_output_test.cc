// What the estimators write before their initialisation (solver/pre_init_output.h): the first standstill's
// rest states as they come, the backward run and the fit's window at the initialisation (forward streams);
// the backward run from the first two-sided state (two-sided streams).
#include "solver/pre_init_output.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/so3.h"

namespace gins {
namespace GINS_TEST_FILE {

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
  for (double t : {1.0, 1.25, 1.5}) pre.Add(RestAt(t), fa, fb);
  EXPECT_EQ(a, (std::vector<double>{1.0, 1.25, 1.5}));
  EXPECT_EQ(b, a);
}

// Once the first standstill is over (rest states more than kBreak apart: the vehicle moved), later rest
// states are only kept: at the initialisation the backward run writes what came after the first
// standstill up to the fit, the rest epochs among its standstills, in time order before the bridge.
TEST(PreInitOutput, ForwardStreamsWaitForTheBackwardRunAfterTheFirstStandstill) {
  InitResult init = StraightInit();
  init.pre_init_fixes.resize(2);
  init.pre_init_fixes[0].t = 4.0;
  init.pre_init_fixes[1].t = 8.0;
  for (int k = 0; k < 1000; ++k) init.pre_init_imu.push_back(ImuSample{0.01 * k, Vec3::Zero(), Vec3::Zero()});
  PreInitOutput pre(kNoise);
  BackwardSpan seen;
  pre.SetBackwardFiller([&](const BackwardSpan& span) {
    seen = span;
    std::vector<StateEstimate> out;
    for (double t : {4.0, 6.0, 8.0, 9.0}) out.push_back(RestAt(t));
    return out;
  });
  std::vector<double> out;
  const StateCallback forward = [&](const StateEstimate& s) { out.push_back(s.x.t); };
  for (double t : {1.0, 1.25, 1.5, 7.0, 7.25, 7.5}) pre.Add(RestAt(t), forward);
  EXPECT_EQ(out, (std::vector<double>{1.0, 1.25, 1.5}));
  pre.Start(init, forward);
  // The span: after the last state written, before the fit's start (10 s), with the later standstill.
  EXPECT_GT(seen.from, 1.5);
  EXPECT_LT(seen.from, 1.5001);
  EXPECT_EQ(seen.start.x.t, 10.0);
  ASSERT_EQ(seen.fixes.size(), 2u);
  EXPECT_EQ(seen.imu.front().t, 1.51);
  EXPECT_EQ(seen.imu.back().t, 9.99);
  ASSERT_EQ(seen.rests.size(), 1u);
  EXPECT_EQ(seen.rests[0], std::make_pair(7.0, 7.5));
  EXPECT_EQ(seen.P, init.fit_start_P);
  ASSERT_GT(out.size(), 7u);
  EXPECT_EQ(std::vector<double>(out.begin(), out.begin() + 7), (std::vector<double>{1.0, 1.25, 1.5, 4.0, 6.0, 8.0, 9.0}));
  EXPECT_NEAR(out[7], 10.0, 1e-9);  // then the bridge from the fit's start
  for (size_t i = 1; i < out.size(); ++i) EXPECT_GT(out[i], out[i - 1]) << i;
}

// At the initialisation the forward streams get the fit's window, bridged through its IMU samples, after
// the last rest state (the detector saw the start late) and before the fit's end (the estimator's own).
TEST(PreInitOutput, ForwardStreamsGetTheFitWindowAtTheInitialisation) {
  const InitResult init = StraightInit();
  PreInitOutput pre(kNoise);
  std::vector<StateEstimate> out;
  const StateCallback forward = [&](const StateEstimate& s) { out.push_back(s); };
  for (double t : {9.8, 10.0, 10.2}) pre.Add(RestAt(t), forward);
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

// The two-sided stream gets, in front of its first state (at the initialisation), the backward run from
// that state over everything since the first fix: the span from the first fix to the initialisation, with
// the standstills, the first state's σ on the diagonal and the fit's bias blocks.
TEST(PreInitOutput, TwoSidedStreamGetsTheBackwardRunFromItsFirstState) {
  InitResult init = StraightInit();
  init.P0.block<6, 6>(nav::kBg, nav::kBg) = 1e-6 * Eigen::Matrix<double, 6, 6>::Identity();
  init.pre_init_fixes.resize(3);
  for (int k = 0; k < 3; ++k) init.pre_init_fixes[k].t = 2.0 + 5.0 * k;  // 2, 7, 12 s
  for (int k = 0; k < 1300; ++k) init.pre_init_imu.push_back(ImuSample{0.01 * k, Vec3::Zero(), Vec3::Zero()});
  PreInitOutput pre(kNoise);
  BackwardSpan seen;
  pre.SetBackwardFiller([&](const BackwardSpan& span) {
    seen = span;
    return std::vector<StateEstimate>{RestAt(2.0), RestAt(12.99)};
  });
  for (double t : {3.0, 3.25, 8.0, 8.25}) pre.Add(RestAt(t), nullptr);
  pre.Start(init, nullptr);
  StateEstimate first;
  first.x = init.x0;
  first.x.q_wb = QuatFromYaw(90.0 * kDegToRad);
  first.sigma_p = Vec3(0.02, 0.03, 0.04);
  first.sigma_v = Vec3::Constant(0.01);
  first.sigma_att = Vec3(0.001, 0.002, 0.004);  // about E, N, U
  std::vector<double> out;
  const StateCallback two_sided = pre.TwoSided([&](const StateEstimate& s) { out.push_back(s.x.t); });
  two_sided(first);
  StateEstimate later = first;
  later.x.t = 13.01;
  two_sided(later);
  EXPECT_EQ(out, (std::vector<double>{2.0, 12.99, 13.0, 13.01}));  // the run once, before the first state
  EXPECT_EQ(seen.start.x.t, 13.0);
  EXPECT_EQ(seen.from, 2.0);
  ASSERT_EQ(seen.fixes.size(), 3u);
  EXPECT_EQ(seen.imu.front().t, 2.0);
  EXPECT_EQ(seen.imu.back().t, 12.99);
  ASSERT_EQ(seen.rests.size(), 2u);
  EXPECT_EQ(seen.rests[0], std::make_pair(3.0, 3.25));
  EXPECT_EQ(seen.rests[1], std::make_pair(8.0, 8.25));
  const Eigen::Matrix<double, 15, 1> d = seen.P.diagonal();
  EXPECT_NEAR(d[nav::kP + 1], 0.03 * 0.03, 1e-15);
  EXPECT_NEAR(d[nav::kV], 1e-4, 1e-15);
  // Yaw 90°: the body's x axis points north, so the rotation about N is the body's about x.
  EXPECT_NEAR(d[nav::kTheta], 0.002 * 0.002, 1e-15);
  EXPECT_NEAR(d[nav::kTheta + 1], 0.001 * 0.001, 1e-15);
  EXPECT_NEAR(d[nav::kTheta + 2], 0.004 * 0.004, 1e-15);
  EXPECT_EQ((seen.P.block<6, 6>(nav::kBg, nav::kBg)), (init.P0.block<6, 6>(nav::kBg, nav::kBg)));
  EXPECT_EQ((seen.P.block<3, 3>(nav::kP, nav::kBg)), Mat3::Zero());
}

// A two-sided stream whose first state is not the initialisation's, or without a fix before it or a
// filler, gets nothing in front.
TEST(PreInitOutput, NothingInFrontWithoutTheInitialisationsStateAFixOrAFiller) {
  for (int c = 0; c < 3; ++c) {
    InitResult init = StraightInit();
    if (c != 1) init.pre_init_fixes.resize(1);
    PreInitOutput pre(kNoise);
    if (c != 2) pre.SetBackwardFiller([](const BackwardSpan&) { return std::vector<StateEstimate>{RestAt(5.0)}; });
    pre.Start(init, nullptr);
    std::vector<double> out;
    const StateCallback two_sided = pre.TwoSided([&](const StateEstimate& s) { out.push_back(s.x.t); });
    StateEstimate first;
    first.x = init.x0;
    if (c == 0) first.x.t = 14.0;
    two_sided(first);
    EXPECT_EQ(out, (std::vector<double>{first.x.t})) << c;
  }
}

}  // namespace
}  // namespace gins
