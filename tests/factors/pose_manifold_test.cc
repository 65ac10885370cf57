#include "factors/pose_manifold.h"

#include <ceres/manifold_test_utils.h>
#include <gtest/gtest.h>

#include <random>

#include "core/nav_state.h"
#include "factor_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

using ceres::HasCorrectMinusJacobianAt;
using ceres::HasCorrectPlusJacobianAt;
using ceres::HasCorrectRightMultiplyByPlusJacobianAt;
using ceres::MinusPlusIsIdentityAt;
using ceres::MinusPlusJacobianIsIdentityAt;
using ceres::PlusMinusIsIdentityAt;
using ceres::Vector;
using ceres::XMinusXIsZeroAt;
using ceres::XPlusZeroIsXAt;

constexpr double kTolerance = 1e-9;

Vector ToVector(const test::PoseBlock& x) { return Eigen::Map<const Vector>(x.data(), 7); }

TEST(PoseManifoldTest, InvariantsHold) {
  std::mt19937 rng(7);
  const PoseManifold manifold;
  for (int trial = 0; trial < 50; ++trial) {
    const test::PoseBlock x_block = test::RandomPose(rng);
    test::PoseBlock y_block = test::RandomPose(rng);
    // q and −q are one pose; take y in the hemisphere Minus maps back to itself.
    if ((PoseRotation(x_block.data()).conjugate() * PoseRotation(y_block.data())).w() < 0.0) {
      for (int i = pose::kQ; i < 7; ++i) y_block[i] = -y_block[i];
    }
    Vec6 delta_tangent;
    delta_tangent << test::RandomVec3(rng, 5.0), test::RandomVec3(rng, 0.5);
    if (trial < 5) delta_tangent.tail<3>() *= 1e-7;  // small-angle branches of Exp/Log
    const Vector x = ToVector(x_block), y = ToVector(y_block);
    const Vector delta = delta_tangent;
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, kTolerance);
  }
}

TEST(PoseManifoldTest, MatchesNavStateBoxplus) {
  std::mt19937 rng(8);
  for (int trial = 0; trial < 20; ++trial) {
    NavState s;
    s.p_wb = test::RandomVec3(rng, 10.0);
    s.q_wb = ExpQuat<double>(test::RandomVec3(rng, 1.0));
    Vec15 d = Vec15::Zero();
    d.segment<3>(nav::kP) = test::RandomVec3(rng, 1.0);
    d.segment<3>(nav::kTheta) = test::RandomVec3(rng, 0.5);
    const NavState t = s.Boxplus(d);
    Vec6 delta;
    delta << d.segment<3>(nav::kP), d.segment<3>(nav::kTheta);
    const test::PoseBlock y = test::PosePlus(test::MakePose(s.p_wb, s.q_wb), delta);
    EXPECT_LT((PosePosition(y.data()) - t.p_wb).norm(), 1e-12);
    EXPECT_LT(LogQuat<double>(t.q_wb.conjugate() * Quat(PoseRotation(y.data()))).norm(), 1e-12);
    Vec6 back;
    PoseManifold().Minus(y.data(), test::MakePose(s.p_wb, s.q_wb).data(), back.data());
    const Vec15 d_back = t.Boxminus(s);
    EXPECT_LT((back.head<3>() - d_back.segment<3>(nav::kP)).norm(), 1e-12);
    EXPECT_LT((back.tail<3>() - d_back.segment<3>(nav::kTheta)).norm(), 1e-12);
  }
}

// MinusJacobianAt(y, x) is ∂Minus(y, x)/∂y away from y = x: check it in y's tangent (x fixed) against
// central differences of Minus(y ⊞ δ, x); there it must equal Jr⁻¹(Minus(y, x)).
TEST(PoseManifoldTest, MinusJacobianAwayFromBasePoint) {
  std::mt19937 rng(9);
  const PoseManifold manifold;
  for (int trial = 0; trial < 20; ++trial) {
    const test::PoseBlock x = test::RandomPose(rng);
    Vec6 d0;
    d0 << test::RandomVec3(rng, 3.0), test::RandomVec3(rng, 0.8);
    const test::PoseBlock y = test::PosePlus(x, d0);
    Eigen::Matrix<double, 6, 7, Eigen::RowMajor> D;
    PoseManifold::MinusJacobianAt(y.data(), x.data(), D.data());
    Eigen::Matrix<double, 7, 6, Eigen::RowMajor> P;
    manifold.PlusJacobian(y.data(), P.data());
    const auto f = [&](const Vec6& d) {
      Vec6 out;
      manifold.Minus(test::PosePlus(y, d).data(), x.data(), out.data());
      return out;
    };
    const Mat6 J_num = test::NumericJacobian<6, 6>(f, 1e-6);
    EXPECT_LT((D * P - J_num).norm(), 1e-7);
    // Radial direction of the quaternion: no change.
    Eigen::Matrix<double, 7, 1> radial = Eigen::Matrix<double, 7, 1>::Zero();
    radial.tail<4>() = Eigen::Map<const Eigen::Vector4d>(y.data() + pose::kQ);
    EXPECT_LT((D * radial).norm(), 1e-12);
  }
}

}  // namespace
}  // namespace gins
