#include "core/so3.h"

#include <gtest/gtest.h>

#include <random>

#include "core/nav_state.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

Vec3 RandomVec(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0.0, scale);
  return Vec3(n(rng), n(rng), n(rng));
}

TEST(So3, ExpLogRoundTrip) {
  std::mt19937 rng(1);
  for (int i = 0; i < 200; ++i) {
    Vec3 phi = RandomVec(rng, i < 50 ? 1e-7 : 1.0);
    if (phi.norm() > 3.0) phi *= 3.0 / phi.norm();
    EXPECT_LT((LogQuat<double>(ExpQuat<double>(phi)) - phi).norm(), 1e-10) << phi.transpose();
  }
}

TEST(So3, ExpMatchesAngleAxis) {
  const Vec3 phi(0.3, -0.2, 1.1);
  const Mat3 R = Eigen::AngleAxisd(phi.norm(), phi.normalized()).toRotationMatrix();
  EXPECT_LT((ExpMat(phi) - R).norm(), 1e-12);
}

TEST(So3, RightJacobianNumeric) {
  std::mt19937 rng(2);
  for (int i = 0; i < 20; ++i) {
    const Vec3 phi = RandomVec(rng, i < 5 ? 1e-6 : 0.8);
    // Exp(φ + δ) ≈ Exp(φ)·Exp(Jr δ)  =>  Log(Exp(φ)ᵀ Exp(φ+δ)) ≈ Jr δ
    const auto f = [&](const Vec3& d) { return Vec3(LogMat(ExpMat(phi).transpose() * ExpMat(phi + d))); };
    const Mat3 J = test::NumericJacobian<3, 3>(f);
    EXPECT_LT((J - RightJacobian(phi)).norm(), 1e-7);
    EXPECT_LT((RightJacobianInverse(phi) * RightJacobian(phi) - Mat3::Identity()).norm(), 1e-9);
  }
}

TEST(So3, LogShortestAngle) {
  const Vec3 phi(0.0, 0.0, 3.0);
  Quat q = ExpQuat<double>(phi);
  q.coeffs() = -q.coeffs();  // same rotation, other hemisphere
  EXPECT_LT((LogQuat<double>(q) - phi).norm(), 1e-12);
}

TEST(NavState, BoxplusBoxminusInverse) {
  std::mt19937 rng(3);
  NavState x;
  x.p_wb = RandomVec(rng, 10);
  x.v_w = RandomVec(rng, 5);
  x.q_wb = ExpQuat<double>(RandomVec(rng, 1.0));
  x.bg = RandomVec(rng, 0.01);
  x.ba = RandomVec(rng, 0.1);
  for (int i = 0; i < 50; ++i) {
    Vec15 d;
    for (int k = 0; k < 15; ++k) d[k] = std::normal_distribution<double>(0, 0.5)(rng);
    const NavState y = x.Boxplus(d);
    EXPECT_LT((y.Boxminus(x) - d).norm(), 1e-10);
    const Vec15 back = x.Boxminus(y);
    EXPECT_LT((y.Boxplus(back).Boxminus(x)).norm(), 1e-9);
  }
  // Right perturbation: the rotation increment acts in the body frame.
  Vec15 d = Vec15::Zero();
  d.segment<3>(nav::kTheta) = Vec3(0, 0, 0.1);
  EXPECT_LT((x.Boxplus(d).R_wb() - x.R_wb() * ExpMat(Vec3(0, 0, 0.1))).norm(), 1e-12);
}

TEST(Conventions, HeadingConversions) {
  EXPECT_NEAR(CompassDegToEnuYaw(0.0), kPi / 2, 1e-12);
  EXPECT_NEAR(CompassDegToEnuYaw(90.0), 0.0, 1e-12);
  EXPECT_NEAR(CompassDegToEnuYaw(180.0), -kPi / 2, 1e-12);
  EXPECT_NEAR(EnuYawToCompassDeg(CompassDegToEnuYaw(271.5)), 271.5, 1e-9);
  EXPECT_NEAR(WrapAngle(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(WrapAngle(-kPi / 2 - 4 * kPi), -kPi / 2, 1e-12);
}

}  // namespace
}  // namespace gins
