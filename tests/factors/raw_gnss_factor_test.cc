// RawAtKeyframeFactor and RawDisplacementFactor (factors/raw_gnss_factor.h): the residual is S·(the antenna's
// position, or displacement, less the constraint's), zero at the constraint's point and blind to the
// directions S does not see; the autodiff Jacobians against numeric differences through the pose manifold.
#include "factors/raw_gnss_factor.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <string>

#include "factor_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

TEST(RawGnssFactorTest, RangeResidualIsTheWhitenedAntennaOffset) {
  std::mt19937 rng(21);
  const Vec3 lever_b(0.0, 0.05, 0.3);
  const test::PoseBlock pose = test::RandomPose(rng);
  const Vec3 vel(1.0, -0.5, 0.1);
  const Vec3 antenna = PosePosition(pose.data()) + Quat(PoseRotation(pose.data())) * lever_b;
  const Vec3 offset(0.4, -0.3, 0.2);
  const Mat3 S = test::SqrtInfoOfRank(2);
  const RawAtKeyframeFactor<RawRangeAtTime> factor(
      RawRangeAtTime{GnssAtTime{antenna - offset, Vec3::Ones(), lever_b}, S});
  Vec3 r;
  ASSERT_TRUE(factor(pose.data(), vel.data(), r.data()));
  EXPECT_LT((r - S * offset).norm(), 1e-9);
  // Along S's null direction the antenna may move freely.
  const Vec3 free = S.row(0).transpose().cross(S.row(1).transpose()).normalized();
  const RawAtKeyframeFactor<RawRangeAtTime> blind(
      RawRangeAtTime{GnssAtTime{antenna + 5.0 * free, Vec3::Ones(), lever_b}, S});
  ASSERT_TRUE(blind(pose.data(), vel.data(), r.data()));
  EXPECT_LT(r.norm(), 1e-9);
}

TEST(RawGnssFactorTest, JacobiansMatchNumeric) {
  std::mt19937 rng(22);
  const PoseManifold manifold;
  const Vec3 lever_b(-0.17, -0.20, 0.3), omega_b(0.1, -0.2, 0.4);
  double worst = 0.0;
  for (int trial = 0; trial < 6; ++trial) {
    const int rank = 1 + trial % 3;
    const test::PoseBlock pose = test::RandomPose(rng);
    const Vec3 vel = test::RandomVec3(rng, 3.0);
    const Vec3 z = PosePosition(pose.data()) + test::RandomVec3(rng, 1.0);
    const std::string what = "rank " + std::to_string(rank);
    std::unique_ptr<ceres::CostFunction> range(RawAtKeyframeFactor<RawRangeAtTime>::Create(
        RawRangeAtTime{GnssAtTime{z, Vec3::Ones(), lever_b}, test::SqrtInfoOfRank(rank)}));
    worst = std::max(worst, test::CheckJacobians(*range, {&manifold, nullptr}, {pose.data(), vel.data()}, 1e-6,
                                                 "raw range " + what));
    std::unique_ptr<ceres::CostFunction> rate(RawAtKeyframeFactor<RawRateAtTime>::Create(
        RawRateAtTime{GnssVelocityAtTime{test::RandomVec3(rng, 3.0), Vec3::Ones(), omega_b, lever_b},
                      test::SqrtInfoOfRank(rank)}));
    worst = std::max(worst, test::CheckJacobians(*rate, {&manifold, nullptr}, {pose.data(), vel.data()}, 1e-6,
                                                 "raw rate " + what));
  }
  std::printf("[ raw gnss jac ] worst relative error: %.2g\n", worst);
}

TEST(RawGnssFactorTest, DisplacementIsTheAntennasBetweenTwoPoses) {
  std::mt19937 rng(23);
  const Vec3 lever_b(0.2, 0.05, 0.8);
  const PoseManifold manifold;
  double worst = 0.0;
  for (int trial = 0; trial < 6; ++trial) {
    const int rank = 1 + trial % 3;
    const Mat3 S = test::SqrtInfoOfRank(rank);
    const test::PoseBlock pose_i = test::RandomPose(rng), pose_j = test::RandomPose(rng);
    const Vec3 d_w = (PosePosition(pose_j.data()) + Quat(PoseRotation(pose_j.data())) * lever_b) -
                     (PosePosition(pose_i.data()) + Quat(PoseRotation(pose_i.data())) * lever_b);
    const Vec3 off = test::RandomVec3(rng, 0.5);
    const RawDisplacementFactor factor(d_w - off, S, lever_b);
    Vec3 r;
    ASSERT_TRUE(factor(pose_i.data(), pose_j.data(), r.data()));
    EXPECT_LT((r - S * off).norm(), 1e-9) << trial;
    std::unique_ptr<ceres::CostFunction> cost(RawDisplacementFactor::Create(d_w - off, S, lever_b));
    worst = std::max(worst, test::CheckJacobians(*cost, {&manifold, &manifold}, {pose_i.data(), pose_j.data()},
                                                 1e-6, "displacement rank " + std::to_string(rank)));
  }
  std::printf("[ raw displacement jac ] worst relative error: %.2g\n", worst);
}

}  // namespace
}  // namespace gins
