// The IMU-rate bridge between two smoothed states (solver/imu_bridge.h).
#include "solver/imu_bridge.h"

#include <gtest/gtest.h>

#include <vector>

#include "core/imu_kernel.h"
#include "core/so3.h"

namespace gins {
namespace GINS_TEST_FILE {

struct Case {
  StateEstimate a;
  std::vector<HeldImuSample> steps;
  ImuEarthTerms earth;
  BridgeNoise noise{1e-3, 1e-2};
};

// One second at 100 Hz, turning and accelerating.
Case MakeCase() {
  Case c;
  c.a.x.t = 10.0;
  c.a.x.v_w = Vec3(5.0, 1.0, 0.0);
  c.a.x.q_wb = ExpQuat<double>(Vec3(0.01, -0.02, 0.7));
  c.a.x.bg = Vec3(1e-3, -2e-3, 5e-4);
  c.a.x.ba = Vec3(0.02, -0.01, 0.03);
  c.a.sigma_p = Vec3(0.02, 0.03, 0.04);
  c.a.sigma_v = Vec3(0.01, 0.01, 0.02);
  c.a.sigma_att = Vec3(1e-3, 1e-3, 3e-3);
  for (int i = 0; i < 100; ++i) {
    HeldImuSample s;
    s.sample.t = c.a.x.t + 0.01 * i;
    s.sample.gyro = Vec3(0.0, 0.0, 0.2) + c.a.x.bg;
    s.sample.acc = Vec3(1.0, 0.1, 9.8) + c.a.x.ba;
    s.dt = 0.01;
    c.steps.push_back(s);
  }
  return c;
}

// Where a alone propagates to at the end of the steps.
StateEstimate PropagatedEnd(const Case& c) {
  Kinematics k{c.a.x.q_wb, c.a.x.v_w, c.a.x.p_wb};
  for (const HeldImuSample& s : c.steps) {
    k = ImuStep(k, s.sample.gyro - c.a.x.bg, s.sample.acc - c.a.x.ba, c.earth.g_w, s.dt, nullptr, c.earth.rate_w);
  }
  StateEstimate b = c.a;
  b.x.t = c.a.x.t + 1.0;
  b.x.q_wb = k.q, b.x.v_w = k.v, b.x.p_wb = k.p;
  return b;
}

TEST(ImuBridge, WithoutMismatchItIsThePropagation) {
  const Case c = MakeCase();
  const StateEstimate b = PropagatedEnd(c);
  std::vector<StateEstimate> bridged, alone;
  EmitBridge(c.a, &b, c.steps, c.earth, c.noise, false, [&](const StateEstimate& e) { bridged.push_back(e); });
  EmitBridge(c.a, nullptr, c.steps, c.earth, c.noise, false, [&](const StateEstimate& e) { alone.push_back(e); });
  ASSERT_EQ(bridged.size(), c.steps.size());  // a and the steps but the last (b emits itself)
  ASSERT_EQ(alone.size(), c.steps.size() + 1);
  for (size_t i = 0; i < bridged.size(); ++i) {
    EXPECT_NEAR(bridged[i].x.t, alone[i].x.t, 1e-12);
    EXPECT_LT((bridged[i].x.p_wb - alone[i].x.p_wb).norm(), 1e-9);
    EXPECT_LT(bridged[i].x.q_wb.angularDistance(alone[i].x.q_wb), 1e-9);
  }
}

TEST(ImuBridge, MeetsTheSecondStateWithTheMismatchSpreadLinearly) {
  const Case c = MakeCase();
  StateEstimate b = PropagatedEnd(c);
  const Vec3 dp(0.3, -0.2, 0.1), dv(0.05, 0.02, -0.01), dphi(0.0, 0.0, 0.01);
  const StateEstimate propagated = b;
  b.x.p_wb += dp;
  b.x.v_w += dv;
  b.x.q_wb = ExpQuat<double>(dphi) * b.x.q_wb;
  b.x.bg += Vec3(1e-4, 0.0, 0.0);
  b.sigma_p = Vec3(0.05, 0.05, 0.05);
  std::vector<StateEstimate> out;
  EmitBridge(c.a, &b, c.steps, c.earth, c.noise, false, [&](const StateEstimate& e) { out.push_back(e); });
  std::vector<StateEstimate> alone;
  EmitBridge(c.a, nullptr, c.steps, c.earth, c.noise, false, [&](const StateEstimate& e) { alone.push_back(e); });
  // The last state before b: 99 % of the mismatch applied; one step further it would be b itself.
  const StateEstimate& last = out.back();
  const double s = 0.99;
  EXPECT_LT((last.x.p_wb - (alone[99].x.p_wb + s * dp)).norm(), 1e-9);
  EXPECT_LT((last.x.v_w - (alone[99].x.v_w + s * dv)).norm(), 1e-9);
  EXPECT_LT((last.x.p_wb - b.x.p_wb).norm(), 0.02 * dp.norm() + 0.06);  // one 10 ms step from b
  EXPECT_NEAR(last.x.bg.x(), c.a.x.bg.x() + s * 1e-4, 1e-12);
  // Midway: half the mismatch, and a σ above both ends' linear share (the bridge's own noise).
  const StateEstimate& mid = out[50];
  EXPECT_LT((mid.x.p_wb - (alone[50].x.p_wb + 0.5 * dp)).norm(), 1e-9);
  const double share = std::sqrt(0.5 * c.a.sigma_p.x() * c.a.sigma_p.x() + 0.5 * b.sigma_p.x() * b.sigma_p.x());
  EXPECT_GT(mid.sigma_p.x(), share);
  EXPECT_LT(mid.sigma_p.x(), share + 0.01);
  // The first state is a itself.
  EXPECT_EQ(out.front().x.p_wb, c.a.x.p_wb);
  EXPECT_EQ(out.front().sigma_p, c.a.sigma_p);
  (void)propagated;
}

TEST(ImuBridge, StandingStillHoldsThePosition) {
  Case c = MakeCase();
  c.a.x.v_w = Vec3(0.3, 0.0, 0.0);  // a wobble the standstill discards
  StateEstimate b = c.a;
  b.x.t = c.a.x.t + 1.0;
  b.x.v_w.setZero();
  std::vector<StateEstimate> out;
  EmitBridge(c.a, &b, c.steps, c.earth, c.noise, true, [&](const StateEstimate& e) { out.push_back(e); });
  for (size_t i = 1; i < out.size(); ++i) {
    EXPECT_LT((out[i].x.p_wb - c.a.x.p_wb).norm(), 1e-12);
    EXPECT_LT(out[i].x.v_w.norm(), 1e-12);
  }
}

}  // namespace
}  // namespace gins
