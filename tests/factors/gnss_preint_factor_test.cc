// A GNSS fix between keyframes, attached to the earlier keyframe through the preintegrated IMU: zero at the
// truth (the kernel's own stepping, with and without Earth rotation), Jacobians against numeric differences.
#include "factors/gnss_preint_factor.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "core/imu_kernel.h"
#include "factor_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

struct Scenario {
  test::PoseBlock pose_i;
  Vec3 vel_i;
  Vec6 bias;
  std::shared_ptr<Preintegration> preint;
  Vec3 antenna_w;  // true antenna position at the fix's time
};

const Vec3 kLever(0.3, -0.2, 1.1);

Scenario Make(const ImuEarthTerms& earth) {
  Scenario s;
  s.bias << 0.01, -0.02, 0.005, 0.1, 0.05, -0.08;
  Kinematics x{ExpQuat<double>(Vec3(0.1, -0.3, 2.0)), Vec3(12.0, 4.0, -0.2), Vec3(10.0, -4.0, 2.0)};
  s.pose_i = test::MakePose(x.p, x.q);
  s.vel_i = x.v;
  s.preint = std::make_shared<Preintegration>(s.bias.head<3>(), s.bias.tail<3>(), 2e-3, 2e-2);
  for (int k = 0; k < 40; ++k) {  // 0.4 s: a 10 Hz fix 0.4 s after its keyframe
    const double t = k * 0.01;
    const Vec3 omega(0.3 * std::sin(2.0 * t), -0.2, 0.5 * std::sin(0.7 * t + 1.0));
    const Vec3 acc(1.0 + 0.5 * std::cos(1.3 * t), 0.4, 9.81 + 0.3 * std::sin(t));
    s.preint->Integrate(omega + s.bias.head<3>(), acc + s.bias.tail<3>(), 0.01);
    x = ImuStep(x, omega, acc, earth.g_w, 0.01, nullptr, earth.rate_w);
  }
  s.antenna_w = x.p + x.q * kLever;
  return s;
}

TEST(GnssPreintFactorTest, ZeroAtTruth) {
  for (const Vec3& rate : {Vec3(Vec3::Zero()), Vec3(7.2921151467e-5 * Vec3(0.0, 0.85, 0.52))}) {
    ImuEarthTerms earth;
    earth.g_w = GravityWorld(9.81);
    earth.rate_w = rate;
    const Scenario s = Make(earth);
    const GnssPreintFactor f(s.preint, earth, s.antenna_w, Vec3::Constant(0.01), kLever);
    Vec3 r;
    f(s.pose_i.data(), s.vel_i.data(), s.bias.data(), r.data());
    // µm: with Earth rate, the closed form's second-order terms (core/preintegration.h)
    EXPECT_LT(r.norm() * 0.01, 1e-5) << "rate " << rate.transpose();
  }
}

TEST(GnssPreintFactorTest, JacobiansMatchNumeric) {
  ImuEarthTerms earth;
  earth.g_w = GravityWorld(9.81);
  earth.rate_w = Vec3(0.01, 0.03, 0.04);  // exaggerated, so its terms show
  const Scenario s = Make(earth);
  const std::unique_ptr<ceres::CostFunction> cost(
      GnssPreintFactor::Create(s.preint, earth, s.antenna_w, Vec3(0.5, 0.6, 0.9), kLever));
  const PoseManifold m;
  std::mt19937 rng(9);
  for (int trial = 0; trial < 6; ++trial) {
    const auto [pose, v, b] = test::PerturbedBlocks(rng, s.pose_i, s.vel_i, s.bias);
    test::CheckJacobians(*cost, {&m, nullptr, nullptr}, {pose.data(), v.data(), b.data()}, 1e-6,
                         "gnss preint " + std::to_string(trial));
  }
}

}  // namespace
}  // namespace gins
