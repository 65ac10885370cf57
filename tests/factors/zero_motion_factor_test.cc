#include "factors/zero_motion_factor.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "factor_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

TEST(ZeroMotionFactorTest, ZeroWhenStillAndScaledBySigma) {
  std::mt19937 rng(21);
  const test::PoseBlock a = test::RandomPose(rng);
  Vec6 r;
  ZeroMotionFactor(0.001, 0.002)(a.data(), a.data(), r.data());
  EXPECT_LT(r.norm(), 1e-12);
  // 2 mm east and 0.01 rad about body z: 2 σ_p and 5 σ_θ.
  Vec6 d;
  d << 0.002, 0.0, 0.0, 0.0, 0.0, 0.01;
  const test::PoseBlock b = test::PosePlus(a, d);
  ZeroMotionFactor(0.001, 0.002)(a.data(), b.data(), r.data());
  Vec6 expected;
  expected << 2.0, 0.0, 0.0, 0.0, 0.0, 5.0;
  EXPECT_LT((r - expected).norm(), 1e-9) << r.transpose();
}

TEST(ZeroMotionFactorTest, JacobiansMatchNumeric) {
  std::mt19937 rng(22);
  const PoseManifold manifold;
  std::unique_ptr<ceres::CostFunction> cost(ZeroMotionFactor::Create(0.001, 0.002));
  double worst = 0.0;
  for (int trial = 0; trial < 10; ++trial) {
    const test::PoseBlock a = test::RandomPose(rng);
    const test::PoseBlock b = test::PosePlus(a, (Vec6() << test::RandomVec3(rng, 0.01), test::RandomVec3(rng, 0.1)).finished());
    worst = std::max(worst, test::CheckJacobians(*cost, {&manifold, &manifold}, {a.data(), b.data()}, 1e-6, "zero motion"));
  }
  std::printf("[ zero motion jac ] worst relative error: %.2g\n", worst);
}

}  // namespace
}  // namespace gins
