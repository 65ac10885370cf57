// The window's predicted covariance over keyframe blocks (solver/smoother_gate.h): the NavState blocks through
// the preintegrated transition, every block outside NavState (scale, time offset) a random walk of its own
// σ, uncorrelated with the rest unless it was before.
#include "solver/smoother_gate.h"

#include <gtest/gtest.h>

#include <vector>

#include "core/imu_kernel.h"
#include "core/so3.h"

namespace gins {
namespace GINS_TEST_FILE {

TEST(PredictBlockCovariance, BlocksOutsideNavStateAreRandomWalksOfTheirOwnSigma) {
  SensorOptions sensors;
  sensors.wheel.enabled = true;
  sensors.wheel.estimate_scale = true;
  sensors.wheel.scale_rw = 2e-4;
  sensors.gnss.estimate_time_offset = true;
  sensors.gnss.time_offset_rw = 3e-3;
  NavState x;
  x.q_wb = ExpQuat<double>(Vec3(0.05, -0.02, 1.0));
  x.v_w = Vec3(8.0, 1.0, 0.0);
  Preintegration pre(x.bg, x.ba, 1e-3, 1e-2);
  for (int k = 0; k < 100; ++k) pre.Integrate(Vec3(0.0, 0.0, 0.1), Vec3(0.5, 0.0, 9.81), 0.01);

  const std::vector<BlockType> nav = {BlockType::kPose, BlockType::kVelocity, BlockType::kBias};
  std::vector<BlockType> all = nav;
  all.push_back(BlockType::kScale);
  all.push_back(BlockType::kTimeOffset);
  const int n = 17;  // 15 + scale + offset
  MatX cov_i = MatX::Identity(n, n) * 1e-2;
  cov_i(15, 16) = cov_i(16, 15) = 4e-3;  // scale and offset correlated at i: kept
  const MatX predicted = PredictBlockCovariance(all, cov_i, x, pre, sensors);
  const MatX nav_only = PredictBlockCovariance(nav, MatX(cov_i.topLeftCorner(15, 15)), x, pre, sensors);
  ASSERT_EQ(predicted.rows(), n);
  EXPECT_LT((predicted.topLeftCorner(15, 15) - nav_only).cwiseAbs().maxCoeff(),
            1e-12 * nav_only.cwiseAbs().maxCoeff());
  EXPECT_NEAR(predicted(15, 15), 1e-2 + 2e-4 * 2e-4 * pre.dt(), 1e-15);
  EXPECT_NEAR(predicted(16, 16), 1e-2 + 3e-3 * 3e-3 * pre.dt(), 1e-15);
  EXPECT_NEAR(predicted(15, 16), 4e-3, 1e-15);
  EXPECT_EQ(predicted.topRightCorner(15, 2).cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace gins
