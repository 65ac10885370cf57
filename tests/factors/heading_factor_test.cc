#include "factors/heading_factor.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "core/so3.h"
#include "factor_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

// Yaw of the antenna frame G = b·Rz(mount_yaw) for a pose.
double AntennaYaw(const test::PoseBlock& pose, double mount_yaw) {
  const Mat3 R_wG =
      Quat(PoseRotation(pose.data())).toRotationMatrix() * QuatFromYaw(mount_yaw).toRotationMatrix();
  return YawOfXAxis<double>(R_wG);
}

TEST(HeadingFactorTest, ResidualAtTruthAndWrap) {
  const double mount_yaw = 12.06 * kDegToRad, sigma = 0.5 * kDegToRad;
  const test::PoseBlock pose = test::MakePose(Vec3(1, 2, 3), ExpQuat<double>(Vec3(0.05, -0.03, 3.1)));
  const double yaw = AntennaYaw(pose, mount_yaw);
  double r = 1.0;
  HeadingFactor(yaw, sigma, mount_yaw)(pose.data(), &r);
  EXPECT_LT(std::abs(r), 1e-12);
  // Across the ±π seam the residual is the short way round.
  HeadingFactor(yaw - 2.0 * kPi + 0.01, sigma, mount_yaw)(pose.data(), &r);
  EXPECT_NEAR(r, -0.01 / sigma, 1e-9);
}

TEST(HeadingFactorTest, JacobiansMatchNumeric) {
  std::mt19937 rng(13);
  const PoseManifold manifold;
  double worst = 0.0;
  for (int trial = 0; trial < 10; ++trial) {
    // Vehicle-like attitudes (roll, pitch within ~0.2 rad): with the antenna axis near vertical the yaw is
    // ill-defined and finite differences of atan2 lose accuracy.
    const Vec3 rpy = test::RandomVec3(rng, 0.1) + Vec3(0.0, 0.0, 3.0 * (trial - 5) / 5.0);
    const test::PoseBlock pose = test::MakePose(test::RandomVec3(rng, 10.0), ExpQuat<double>(rpy));
    const double yaw_meas = AntennaYaw(pose, 0.2) + (trial == 0 ? 0.0 : 0.1 * (trial - 5));
    std::unique_ptr<ceres::CostFunction> cost(HeadingFactor::Create(yaw_meas, 0.01, 0.2));
    worst = std::max(worst, test::CheckJacobians(*cost, {&manifold}, {pose.data()}, 1e-6, "heading"));
  }
  std::printf("[ head jac ] worst relative error: %.2g\n", worst);
}

}  // namespace
}  // namespace gins
