#include "core/imu_kernel.h"

#include <gtest/gtest.h>

#include "core/so3.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

// Error of the propagated state, in the kernel's order (δp, δv, δθ), relative to the nominal step.
Vec9 StepError(const Kinematics& nominal_out, const Kinematics& perturbed_out) {
  Vec9 e;
  e.segment<3>(0) = perturbed_out.p - nominal_out.p;
  e.segment<3>(3) = perturbed_out.v - nominal_out.v;
  e.segment<3>(6) = LogQuat<double>(nominal_out.q.conjugate() * perturbed_out.q);
  return e;
}

class ImuKernelTest : public ::testing::Test {
 protected:
  Kinematics x{ExpQuat<double>(Vec3(0.2, -0.1, 1.3)), Vec3(3.0, -1.0, 0.2), Vec3(10.0, 20.0, -1.0)};
  Vec3 omega{0.3, -0.2, 0.5};
  Vec3 acc{0.4, 0.1, 9.9};
  Vec3 g{0.0, 0.0, -9.81};
  double dt = 0.01;
};

TEST_F(ImuKernelTest, StateJacobianMatchesNumeric) {
  ImuStepJacobians J;
  const Kinematics y = ImuStep(x, omega, acc, g, dt, &J);
  const auto f = [&](const Vec9& d) {
    Kinematics xp = x;
    xp.p += d.segment<3>(0);
    xp.v += d.segment<3>(3);
    xp.q = x.q * ExpQuat<double>(Vec3(d.segment<3>(6)));
    return StepError(y, ImuStep(xp, omega, acc, g, dt));
  };
  EXPECT_LT((test::NumericJacobian<9, 9>(f) - J.A).cwiseAbs().maxCoeff(), 1e-6);
}

TEST_F(ImuKernelTest, BiasAndGravityJacobiansMatchNumeric) {
  ImuStepJacobians J;
  const Kinematics y = ImuStep(x, omega, acc, g, dt, &J);
  // A bias error δb means the true rate is ω − δbg (the estimate's correction was short by δb).
  const auto fb = [&](const Vec6& d) {
    return StepError(y, ImuStep(x, omega - d.head<3>(), acc - d.tail<3>(), g, dt));
  };
  EXPECT_LT((test::NumericJacobian<9, 6>(fb) - J.B).cwiseAbs().maxCoeff(), 1e-8);
  const auto fg = [&](const Vec3& d) { return StepError(y, ImuStep(x, omega, acc, g + d, dt)); };
  EXPECT_LT((test::NumericJacobian<9, 3>(fg) - J.G).cwiseAbs().maxCoeff(), 1e-8);
}

TEST_F(ImuKernelTest, ConstantMotionIsExactForPositionAndVelocity) {
  // Zero rotation rate: the first-order step is exact.
  const Kinematics y = ImuStep(x, Vec3::Zero(), acc, g, 0.5);
  const Vec3 a_w = x.q * acc + g;
  EXPECT_LT((y.v - (x.v + a_w * 0.5)).norm(), 1e-12);
  EXPECT_LT((y.p - (x.p + x.v * 0.5 + 0.125 * a_w)).norm(), 1e-12);
}

// The structured products equal the dense ones: they may skip only blocks ImuStep leaves zero or identity.
TEST_F(ImuKernelTest, StructuredProductsEqualDenseOnes) {
  ImuStepJacobians J;
  ImuStep(x, omega, acc, g, dt, &J);
  const Eigen::Matrix<double, 9, 7> X = Eigen::Matrix<double, 9, 7>::Random();
  EXPECT_LT((MulA<7>(J, X) - J.A * X).cwiseAbs().maxCoeff(), 1e-14);
  const Eigen::Matrix<double, 9, 7> Y = Eigen::Matrix<double, 9, 7>::Random();
  const Eigen::Matrix<double, 9, 7> with_g = J.B * Y.topRows<6>() + J.G * Y.bottomRows<3>();
  EXPECT_LT((MulBG<7>(J, Y, true) - with_g).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((MulBG<7>(J, Y, false) - J.B * Y.topRows<6>()).cwiseAbs().maxCoeff(), 1e-14);
  // Transposed: XT·Aᵀ and YT·[B G]ᵀ.
  EXPECT_LT((MulAT<7>(J, X.transpose()) - X.transpose() * J.A.transpose()).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((MulBGT<7>(J, Y.transpose(), true) - with_g.transpose()).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((MulBGT<7>(J, Y.transpose(), false) - (J.B * Y.topRows<6>()).transpose()).cwiseAbs().maxCoeff(),
            1e-14);
  // On a block of a larger matrix, without a copy.
  Eigen::Matrix<double, 12, 7> big = Eigen::Matrix<double, 12, 7>::Random();
  EXPECT_LT((MulA<7>(J, big.middleRows<9>(2)) - J.A * big.middleRows<9>(2)).cwiseAbs().maxCoeff(), 1e-14);
  // The sensor noise B·diag(q)·Bᵀ, added into a block.
  const Vec6 q = Vec6::Random().cwiseAbs();
  Eigen::Matrix<double, 11, 11> P = Eigen::Matrix<double, 11, 11>::Random();
  const Eigen::Matrix<double, 11, 11> P0 = P;
  AddDrivingNoise(J, q, P.block<9, 9>(1, 2));
  const Mat9 dense = J.B * q.asDiagonal() * J.B.transpose();
  EXPECT_LT((P.block<9, 9>(1, 2) - P0.block<9, 9>(1, 2) - dense).cwiseAbs().maxCoeff(), 1e-14);
  P.block<9, 9>(1, 2) = P0.block<9, 9>(1, 2);
  EXPECT_EQ(P, P0);  // nothing outside the block
}

TEST(ImuDiscreteNoise, ScalesWithRate) {
  const Mat6 Q = ImuDiscreteNoise(0.01, 0.1, 0.01);
  EXPECT_NEAR(Q(0, 0), 0.01 * 0.01 / 0.01, 1e-15);
  EXPECT_NEAR(Q(5, 5), 0.1 * 0.1 / 0.01, 1e-15);
  EXPECT_EQ(Q(0, 3), 0.0);
}

}  // namespace
}  // namespace gins

namespace gins {
namespace GINS_TEST_FILE {

// With Earth rotation the kernel adds Coriolis and turns w under the body; its Jacobians still match
// numeric differences (an exaggerated rate makes the terms visible), and the structured products still
// equal the dense ones.
TEST_F(ImuKernelTest, EarthRotationJacobiansMatchNumeric) {
  const Vec3 rate(0.01, 0.03, 0.04);
  ImuStepJacobians J;
  const Kinematics y = ImuStep(x, omega, acc, g, dt, &J, rate);
  EXPECT_TRUE(J.coriolis);
  const auto f = [&](const Vec9& d) {
    Kinematics xp = x;
    xp.p += d.segment<3>(0);
    xp.v += d.segment<3>(3);
    xp.q = x.q * ExpQuat<double>(Vec3(d.segment<3>(6)));
    return StepError(y, ImuStep(xp, omega, acc, g, dt, nullptr, rate));
  };
  EXPECT_LT((test::NumericJacobian<9, 9>(f) - J.A).cwiseAbs().maxCoeff(), 1e-6);
  const auto fb = [&](const Vec6& d) {
    return StepError(y, ImuStep(x, omega - d.head<3>(), acc - d.tail<3>(), g, dt, nullptr, rate));
  };
  EXPECT_LT((test::NumericJacobian<9, 6>(fb) - J.B).cwiseAbs().maxCoeff(), 1e-8);
  const Eigen::Matrix<double, 9, 7> X = Eigen::Matrix<double, 9, 7>::Random();
  EXPECT_LT((MulA<7>(J, X) - J.A * X).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((MulAT<7>(J, X.transpose()) - X.transpose() * J.A.transpose()).cwiseAbs().maxCoeff(), 1e-14);
}

TEST_F(ImuKernelTest, EarthRotationTurnsTheWorldFrame) {
  // At rest on the rotating Earth the gyro reads Rᵀω_ie and the accelerometer −Rᵀg: w must not move.
  const Vec3 rate = 7.2921151467e-5 * Vec3(0.0, 0.8, 0.6);
  Kinematics k{x.q, Vec3::Zero(), Vec3(1.0, 2.0, 3.0)};
  for (int i = 0; i < 1000; ++i) {
    k = ImuStep(k, x.q.conjugate() * rate, x.q.conjugate() * -g, g, 0.01, nullptr, rate);
  }
  EXPECT_LT(LogQuat<double>(x.q.conjugate() * k.q).norm(), 1e-12);
  EXPECT_LT(k.v.norm(), 1e-10);
  // Moving east at 20 m/s, Coriolis pushes the velocity sideways by 2ω×v·t.
  Kinematics m{Quat::Identity(), Vec3(20.0, 0.0, 0.0), Vec3::Zero()};
  const Kinematics m1 = ImuStep(m, rate, -g, g, 1.0, nullptr, rate);
  EXPECT_LT((m1.v - (m.v - 2.0 * rate.cross(m.v))).norm(), 1e-12);
}

}  // namespace
}  // namespace gins
