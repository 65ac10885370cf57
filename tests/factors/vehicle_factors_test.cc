// The vehicle factors between keyframes (odometer, chord, wheel yaw) and at a keyframe (NHC with a lever
// arm, GNSS velocity): zero at a consistent truth, Jacobians against numeric differences in tangent space.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "factor_test_util.h"
#include "factors/chord_factor.h"
#include "factors/gnss_velocity_factor.h"
#include "factors/nhc_factor.h"
#include "factors/odometer_factor.h"
#include "factors/wheel_yaw_factor.h"

namespace gins {
namespace GINS_TEST_FILE {

const Vec3 kLever(-1.5, 0.1, -0.3);  // rear-axle centre 1.5 m behind the IMU

// A car on a circle of radius ρ at speed v, level: the axle centre follows the circle, the body x axis is
// tangent to it. Returns the IMU pose at time t (the IMU is at −lever from the axle centre).
test::PoseBlock ArcPose(double rho, double v, double t) {
  const double psi = v * t / rho;
  const Vec3 axle(rho * std::sin(psi), rho * (1.0 - std::cos(psi)), 0.0);
  const Quat q = QuatFromYaw(psi);
  return test::MakePose(axle - q * kLever, q);
}

TEST(VehicleFactorsTest, ZeroOnAnArc) {
  const double rho = 30.0, v = 10.0, dt = 1.0;
  const test::PoseBlock pi = ArcPose(rho, v, 0.0), pj = ArcPose(rho, v, dt);
  const double scale = 0.99;
  // The encoders: distance along the arc, in the body frame at i (summed over 100 small steps).
  Vec3 D = Vec3::Zero();
  double yaw = 0.0;
  for (int k = 0; k < 100; ++k) {
    const double psi_mid = v * (k + 0.5) * 0.01 / rho;
    D += scale * v * 0.01 * Vec3(std::cos(psi_mid), std::sin(psi_mid), 0.0);
    yaw += scale * v * 0.01 / rho;
  }
  double r1 = 0.0;
  OdometerFactor(D, 0.01, kLever)(pi.data(), pj.data(), &scale, &r1);
  // D sums the encoder steps as vectors, so it is the chord too: what is left is the steps' discretisation.
  EXPECT_LT(std::abs(r1) * 0.01, 1e-5);
  Vec2 r2;
  ChordFactor(dt, 0.1, kLever, D)(pi.data(), pj.data(), r2.data());
  EXPECT_LT(r2.norm() * 0.1, 1e-5);
  WheelYawFactor(yaw, 0.01)(pi.data(), pj.data(), &scale, &r1);
  EXPECT_LT(std::abs(r1), 1e-9);
  // The IMU, 1.5 m ahead of the axle, slides sideways in the turn; the axle centre does not.
  const Quat q(PoseRotation(pi.data()));
  const Vec3 omega_b(0.0, 0.0, v / rho);
  const Vec3 v_imu = q * (Vec3(v, 0.0, 0.0) - omega_b.cross(kLever));
  NhcFactor(0.1, omega_b, kLever)(pi.data(), v_imu.data(), r2.data());
  EXPECT_LT(r2.norm(), 1e-9);
  NhcFactor(0.1)(pi.data(), v_imu.data(), r2.data());
  EXPECT_GT(r2.norm(), 4.0);  // without the lever arm: 0.5 m/s of phantom slip
  // GNSS velocity of an antenna on the roof.
  const Vec3 lever_ant(0.5, -0.3, 1.2);
  const Vec3 z = v_imu + q * omega_b.cross(lever_ant);
  Vec3 r3;
  GnssVelocityFactor(z, Vec3::Constant(0.05), omega_b, lever_ant)(pi.data(), v_imu.data(), r3.data());
  EXPECT_LT(r3.norm(), 1e-9);
}

// Entering a turn while speeding up (yaw rate and speed both ramp): the axle's chord leaves the body x axis
// halfway between the two attitudes by more than the constraint's σ, but points along the path the body x
// axis traced, weighted by the speed (ChordModel), to the integration's accuracy.
TEST(VehicleFactorsTest, ChordAlongThePathWhenTheTurnTightens) {
  const double dt = 1.1, v0 = 8.0, accel = 1.5, yaw_accel = 0.6;  // m/s, m/s², rad/s²
  const int steps = 11000;
  Vec3 axle = Vec3::Zero(), path = Vec3::Zero();
  for (int k = 0; k < steps; ++k) {
    const double t = (k + 0.5) * dt / steps;
    const Vec3 step = (v0 + accel * t) * dt / steps * (QuatFromYaw(0.5 * yaw_accel * t * t) * Vec3::UnitX());
    axle += step;
    path += step;  // the body frame at i is the world's here
  }
  const Quat q_j = QuatFromYaw(0.5 * yaw_accel * dt * dt);
  const test::PoseBlock pi = test::MakePose(-kLever, Quat::Identity());
  const test::PoseBlock pj = test::MakePose(axle - q_j * kLever, q_j);
  Vec2 r;
  ChordFactor(dt, 0.01, kLever, path)(pi.data(), pj.data(), r.data());
  EXPECT_LT(r.norm(), 1e-3);  // 1e-5 m/s against σ = 0.01 m/s
  // Against the attitude halfway instead: 0.53 m across the 9.6 m chord, 0.48 m/s on average.
  const Vec3 halfway = QuatFromYaw(0.25 * yaw_accel * dt * dt) * Vec3::UnitX();
  ChordFactor(dt, 0.01, kLever, halfway)(pi.data(), pj.data(), r.data());
  EXPECT_GT(std::abs(r.x()) * 0.01, 0.4);
}

TEST(VehicleFactorsTest, ChordBasis) {
  Eigen::Matrix<double, 2, 3> n = ChordModel::Basis(Vec3(3.0, 0.0, 0.0));
  EXPECT_TRUE(n.row(0).isApprox(Vec3::UnitY().transpose()));
  EXPECT_TRUE(n.row(1).isApprox(Vec3::UnitZ().transpose()));
  // A standstill (no path) and reversing (the path behind): the body's own lateral and vertical axes.
  n = ChordModel::Basis(Vec3(1e-4, 2e-4, 0.0));
  EXPECT_TRUE(n.row(0).isApprox(Vec3::UnitY().transpose()));
  n = ChordModel::Basis(Vec3(-2.0, 0.0, 0.0));
  EXPECT_TRUE(n.row(0).cwiseAbs().isApprox(Vec3::UnitY().transpose()));
  EXPECT_TRUE(n.row(1).isApprox(Vec3::UnitZ().transpose()));
  // Any path: two unit rows, orthogonal to each other and to the path; even straight up.
  for (const Vec3& u : {Vec3(5.0, 1.0, -0.4), Vec3(-0.3, 2.0, 0.5), Vec3(0.01, 0.0, 3.0)}) {
    n = ChordModel::Basis(u);
    EXPECT_NEAR((n * n.transpose() - Eigen::Matrix2d::Identity()).norm(), 0.0, 1e-12);
    EXPECT_NEAR((n * u).norm(), 0.0, 1e-12);
  }
}

// The analytic Jacobians of the chord and odometer factors against autodiff of the same residual, in the
// tangent (ambient pose Jacobians may differ along the quaternion's radial direction, which Ceres never uses).
TEST(VehicleFactorsTest, AnalyticJacobiansMatchAutoDiff) {
  std::mt19937 rng(5);
  const PoseManifold m;
  const Vec3 D(9.8, 0.5, 0.1);
  const std::unique_ptr<ceres::CostFunction> chord(ChordFactor::Create(0.8, 0.1, kLever, D));
  const std::unique_ptr<ceres::CostFunction> chord_ad(ChordFactor::CreateAutoDiff(0.8, 0.1, kLever, D));
  const std::unique_ptr<ceres::CostFunction> odo(OdometerFactor::Create(D, 0.02, kLever));
  const std::unique_ptr<ceres::CostFunction> odo_ad(OdometerFactor::CreateAutoDiff(D, 0.02, kLever));
  for (int trial = 0; trial < 8; ++trial) {
    const test::PoseBlock pi = test::RandomPose(rng);
    const test::PoseBlock pj = test::RandomPoseNear(rng, pi, 5.0, 0.4);
    const double s = 0.97 + 0.01 * trial;
    const std::string what = "trial " + std::to_string(trial);
    test::ExpectSameResidualAndJacobians(*chord, *chord_ad, {&m, &m}, {pi.data(), pj.data()}, "chord " + what);
    test::ExpectSameResidualAndJacobians(*odo, *odo_ad, {&m, &m, nullptr}, {pi.data(), pj.data(), &s},
                                         "odometer " + what);
  }
}

TEST(VehicleFactorsTest, JacobiansMatchNumeric) {
  std::mt19937 rng(23);
  const PoseManifold m;
  const std::unique_ptr<ceres::CostFunction> odo(OdometerFactor::Create(Vec3(9.8, 0.5, 0.1), 0.02, kLever));
  const std::unique_ptr<ceres::CostFunction> chord(ChordFactor::Create(0.8, 0.1, kLever, Vec3(7.9, 0.6, -0.2)));
  const std::unique_ptr<ceres::CostFunction> yaw(WheelYawFactor::Create(0.3, 0.01));
  const std::unique_ptr<ceres::CostFunction> nhc(NhcFactor::Create(0.1, Vec3(0.01, -0.02, 0.3), kLever));
  const std::unique_ptr<ceres::CostFunction> gnss_velocity(
      GnssVelocityFactor::Create(Vec3(3, 4, 0.1), Vec3(0.05, 0.05, 0.1), Vec3(0.01, -0.02, 0.3), Vec3(0.5, -0.3, 1.2)));
  for (int trial = 0; trial < 8; ++trial) {
    const test::PoseBlock pi = test::RandomPose(rng);
    const test::PoseBlock pj = test::RandomPoseNear(rng, pi, 5.0, 0.4);
    const double s = 1.0 + 0.02 * trial;
    const Vec3 v = test::RandomVec3(rng, 8.0);
    const std::string what = "trial " + std::to_string(trial);
    test::CheckJacobians(*odo, {&m, &m, nullptr}, {pi.data(), pj.data(), &s}, 1e-6, "odometer " + what);
    test::CheckJacobians(*chord, {&m, &m}, {pi.data(), pj.data()}, 1e-6, "chord " + what);
    test::CheckJacobians(*yaw, {&m, &m, nullptr}, {pi.data(), pj.data(), &s}, 1e-6, "wheel yaw " + what);
    test::CheckJacobians(*nhc, {&m, nullptr}, {pi.data(), v.data()}, 1e-6, "nhc " + what);
    test::CheckJacobians(*gnss_velocity, {&m, nullptr}, {pi.data(), v.data()}, 1e-6, "gvel " + what);
  }
}

}  // namespace
}  // namespace gins
