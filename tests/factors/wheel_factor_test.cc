#include "factors/wheel_factor.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "factor_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

TEST(WheelFactorTest, ResidualAtTruth) {
  std::mt19937 rng(14);
  const test::PoseBlock pose = test::RandomPose(rng);
  const Quat q_wb(PoseRotation(pose.data()));
  const Vec3 v_w = q_wb * Vec3(8.0, 0.0, 0.0);
  const double scale = 0.99;
  double r = 1.0;
  WheelFactor(scale * 8.0, 0.1)(pose.data(), v_w.data(), &scale, &r);
  EXPECT_LT(std::abs(r), 1e-12);
  WheelFactor(scale * 8.0 - 0.1, 0.1)(pose.data(), v_w.data(), &scale, &r);
  EXPECT_NEAR(r, 1.0, 1e-9);
}

TEST(WheelFactorTest, JacobiansMatchNumeric) {
  std::mt19937 rng(15);
  const PoseManifold manifold;
  double worst = 0.0;
  for (int trial = 0; trial < 10; ++trial) {
    const test::PoseBlock pose = test::RandomPose(rng);
    const Vec3 v_w = test::RandomVec3(rng, 5.0);
    const double scale = 1.0 + 0.05 * (trial - 5);
    std::unique_ptr<ceres::CostFunction> cost(WheelFactor::Create(4.0, 0.1));
    worst = std::max(worst, test::CheckJacobians(*cost, {&manifold, nullptr, nullptr},
                                                 {pose.data(), v_w.data(), &scale}, 1e-6, "wheel"));
  }
  std::printf("[ wheel jac] worst relative error: %.2g\n", worst);
}

}  // namespace
}  // namespace gins
