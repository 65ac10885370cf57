#include "factors/nhc_factor.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "factor_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

TEST(NhcFactorTest, ResidualAtTruth) {
  std::mt19937 rng(16);
  const test::PoseBlock pose = test::RandomPose(rng);
  const Quat q_wb(PoseRotation(pose.data()));
  Vec2 r;
  const Vec3 v_forward = q_wb * Vec3(8.0, 0.0, 0.0);
  NhcFactor(0.1)(pose.data(), v_forward.data(), r.data());
  EXPECT_LT(r.norm(), 1e-12);
  const Vec3 v_slip = q_wb * Vec3(8.0, 0.1, -0.2);
  NhcFactor(0.1)(pose.data(), v_slip.data(), r.data());
  EXPECT_LT((r - Vec2(1.0, -2.0)).norm(), 1e-9);
}

TEST(NhcFactorTest, JacobiansMatchNumeric) {
  std::mt19937 rng(17);
  const PoseManifold manifold;
  std::unique_ptr<ceres::CostFunction> cost(NhcFactor::Create(0.1));
  double worst = 0.0;
  for (int trial = 0; trial < 10; ++trial) {
    const test::PoseBlock pose = test::RandomPose(rng);
    const Vec3 v_w = test::RandomVec3(rng, 5.0);
    worst = std::max(
        worst, test::CheckJacobians(*cost, {&manifold, nullptr}, {pose.data(), v_w.data()}, 1e-6, "nhc"));
  }
  std::printf("[ nhc jac  ] worst relative error: %.2g\n", worst);
}

}  // namespace
}  // namespace gins
