#include "factors/gnss_factor.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "factor_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

TEST(GnssFactorTest, ResidualAtTruthAndWhitening) {
  std::mt19937 rng(11);
  const Vec3 lever_b(-0.17, -0.20, 0.3), sigma_w(0.02, 0.03, 0.05);
  const test::PoseBlock pose = test::RandomPose(rng);
  const Vec3 z_w = PosePosition(pose.data()) + Quat(PoseRotation(pose.data())) * lever_b;
  const GnssFactor factor(z_w, sigma_w, lever_b);
  Vec3 r;
  ASSERT_TRUE(factor(pose.data(), r.data()));
  EXPECT_LT(r.norm(), 1e-12);
  // A 1-σ offset per axis gives a unit residual per axis.
  const GnssFactor offset(z_w + sigma_w, sigma_w, lever_b);
  offset(pose.data(), r.data());
  EXPECT_LT((r + Vec3::Ones()).norm(), 1e-9);
}

TEST(GnssFactorTest, JacobiansMatchNumeric) {
  std::mt19937 rng(12);
  const PoseManifold manifold;
  const Vec3 lever_b(-0.17, -0.20, 0.3);
  double worst = 0.0;
  for (int trial = 0; trial < 10; ++trial) {
    const test::PoseBlock pose = test::RandomPose(rng);
    const Vec3 z_w = PosePosition(pose.data()) + Quat(PoseRotation(pose.data())) * lever_b +
                     (trial == 0 ? Vec3::Zero() : test::RandomVec3(rng, 1.0));
    std::unique_ptr<ceres::CostFunction> cost(GnssFactor::Create(z_w, Vec3(0.02, 0.03, 0.05), lever_b));
    worst = std::max(worst, test::CheckJacobians(*cost, {&manifold}, {pose.data()}, 1e-6, "gnss"));
  }
  std::printf("[ gnss jac ] worst relative error: %.2g\n", worst);
}

}  // namespace
}  // namespace gins
