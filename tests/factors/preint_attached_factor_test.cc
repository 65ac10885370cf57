// The analytic Jacobians of PreintAttachedCostFunction, for every measurement it carries, flat and rotating
// Earth: equal to autodiff of the same residual (PreintAttachedFactor::CreateAutoDiff) to rounding, and to
// numeric differences through the pose manifold, at states away from the linearisation point (bias off its
// preintegration point, so the first-order bias correction and its Jr(φ) matter).
#include "factors/preint_attached_factor.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "factor_test_util.h"
#include "factors/raw_gnss_factor.h"

namespace gins {
namespace GINS_TEST_FILE {

template <class Measurement>
void ExpectAnalyticMatches(const Measurement& measurement, const std::string& what) {
  // Zero and an exaggerated Earth rate (its terms must show above the tolerance).
  for (const Vec3& rate : {Vec3(Vec3::Zero()), Vec3(0.01, 0.03, 0.04)}) {
    const test::AttachedInterval s = test::MakeAttachedInterval(rate);
    const std::unique_ptr<ceres::CostFunction> analytic(
        PreintAttachedFactor<Measurement>::Create(s.preint, s.earth, measurement));
    const std::unique_ptr<ceres::CostFunction> autodiff(
        PreintAttachedFactor<Measurement>::CreateAutoDiff(s.preint, s.earth, measurement));
    constexpr int M = Measurement::kResidualDim;
    const PoseManifold manifold;
    std::mt19937 rng(17);
    for (int trial = 0; trial < 8; ++trial) {
      const auto [pose, v, b] = test::PerturbedBlocks(rng, s.pose_i, s.vel_i, s.bias);
      const double* params[] = {pose.data(), v.data(), b.data()};
      Eigen::Matrix<double, M, 1> r_a, r_d;
      Eigen::Matrix<double, M, 7, Eigen::RowMajor> Jp_a, Jp_d;
      Eigen::Matrix<double, M, 3, Eigen::RowMajor> Jv_a, Jv_d;
      Eigen::Matrix<double, M, 6, Eigen::RowMajor> Jb_a, Jb_d;
      double* J_a[] = {Jp_a.data(), Jv_a.data(), Jb_a.data()};
      double* J_d[] = {Jp_d.data(), Jv_d.data(), Jb_d.data()};
      ASSERT_TRUE(analytic->Evaluate(params, r_a.data(), J_a));
      ASSERT_TRUE(autodiff->Evaluate(params, r_d.data(), J_d));
      const std::string at = what + " rate " + std::to_string(rate.norm()) + " trial " + std::to_string(trial);
      EXPECT_LT((r_a - r_d).norm(), 1e-9 * (1.0 + r_d.norm())) << at;
      // Ambient pose Jacobians differ in the quaternion's normal direction only, which the manifold's
      // PlusJacobian removes: compare in the tangent.
      Eigen::Matrix<double, 7, 6, Eigen::RowMajor> lift;
      ASSERT_TRUE(manifold.PlusJacobian(pose.data(), lift.data()));
      const auto Jt_a = (Jp_a * lift).eval(), Jt_d = (Jp_d * lift).eval();
      const double scale = 1.0 + Jt_d.cwiseAbs().maxCoeff() + Jv_d.cwiseAbs().maxCoeff() + Jb_d.cwiseAbs().maxCoeff();
      EXPECT_LT((Jt_a - Jt_d).cwiseAbs().maxCoeff(), 1e-9 * scale) << at << " pose\n" << Jt_a << "\n" << Jt_d;
      EXPECT_LT((Jv_a - Jv_d).cwiseAbs().maxCoeff(), 1e-9 * scale) << at << " velocity";
      EXPECT_LT((Jb_a - Jb_d).cwiseAbs().maxCoeff(), 1e-9 * scale) << at << " bias\n" << Jb_a << "\n" << Jb_d;
      test::CheckJacobians(*analytic, {&manifold, nullptr, nullptr}, {pose.data(), v.data(), b.data()}, 1e-6,
                           at + " numeric");
    }
  }
}

TEST(PreintAttachedCostFunctionTest, GnssPositionMatchesAutodiffAndNumeric) {
  ExpectAnalyticMatches(GnssAtTime{Vec3(20.0, -1.0, 0.5), Vec3(2.0, 1.5, 1.0), Vec3(0.3, -0.2, 1.1)}, "gnss");
}

TEST(PreintAttachedCostFunctionTest, HeadingMatchesAutodiffAndNumeric) {
  ExpectAnalyticMatches(HeadingAtTime{1.7, 1.0 / 0.02, 0.3}, "heading");
}

TEST(PreintAttachedCostFunctionTest, GnssVelocityMatchesAutodiffAndNumeric) {
  ExpectAnalyticMatches(
      GnssVelocityAtTime{Vec3(9.0, -3.0, 2.5), Vec3(10.0, 10.0, 5.0), Vec3(0.1, -0.2, 0.4), Vec3(0.3, -0.2, 1.1)}, "gvel");
}

// A raw epoch's constraint at full rank and below (zero rows: directions the satellites do not see).
TEST(PreintAttachedCostFunctionTest, RawRangeMatchesAutodiffAndNumeric) {
  for (int rank : {3, 2}) {
    ExpectAnalyticMatches(
        RawRangeAtTime{GnssAtTime{Vec3(20.0, -1.0, 0.5), Vec3::Ones(), Vec3(0.3, -0.2, 1.1)},
                       test::SqrtInfoOfRank(rank)},
        "raw range rank " + std::to_string(rank));
  }
}

TEST(PreintAttachedCostFunctionTest, RawRateMatchesAutodiffAndNumeric) {
  for (int rank : {3, 1}) {
    ExpectAnalyticMatches(RawRateAtTime{GnssVelocityAtTime{Vec3(9.0, -3.0, 2.5), Vec3::Ones(), Vec3(0.1, -0.2, 0.4),
                                                           Vec3(0.3, -0.2, 1.1)},
                                        test::SqrtInfoOfRank(rank)},
                          "raw rate rank " + std::to_string(rank));
  }
}

}  // namespace
}  // namespace gins
