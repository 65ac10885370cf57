// The shared measurement models: residual zero at truth, and the tangent-space Jacobians the ESKF gets
// from core/linearize.h against central differences taken through the same ⊞.
#include <gtest/gtest.h>

#include <random>

#include "core/gnss_model.h"
#include "core/heading_model.h"
#include "core/linearize.h"
#include "core/so3.h"
#include "core/wheel_model.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

struct State {
  Vec3 p_wb, v_w;
  Quat q_wb;
  double scale;
};

State RandomState(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  State s;
  s.p_wb = Vec3(n(rng), n(rng), n(rng)) * 20.0;
  s.v_w = Vec3(n(rng), n(rng), n(rng)) * 5.0;
  s.q_wb = ExpQuat<double>(Vec3(0.2 * n(rng), 0.2 * n(rng), 3.0 * n(rng)));
  s.scale = 1.0 + 0.02 * n(rng);
  return s;
}

// Perturbation δ = (δp, δv, δθ, δs) applied through ⊞.
template <typename T>
void Perturb(const State& s, const Eigen::Matrix<T, 10, 1>& d, Eigen::Matrix<T, 3, 1>* p, Eigen::Matrix<T, 3, 1>* v,
             Eigen::Quaternion<T>* q, T* scale) {
  *p = s.p_wb.cast<T>() + d.template segment<3>(0);
  *v = s.v_w.cast<T>() + d.template segment<3>(3);
  *q = s.q_wb.cast<T>() * ExpQuat<T>(Eigen::Matrix<T, 3, 1>(d.template segment<3>(6)));
  *scale = T(s.scale) + d[9];
}

template <int M, typename Residual>
void CheckJacobian(const Residual& residual, double tol) {
  Eigen::Matrix<double, M, 1> r0;
  Eigen::Matrix<double, M, 10> H;
  Linearize<M, 10>([&](const auto& d) { return residual(d); }, &r0, &H);
  const auto f = [&](const Eigen::Matrix<double, 10, 1>& d) { return Eigen::Matrix<double, M, 1>(residual(d)); };
  const Eigen::Matrix<double, M, 10> H_num = test::NumericJacobian<M, 10>(f);
  EXPECT_LT((H - H_num).cwiseAbs().maxCoeff(), tol) << "analytic\n" << H << "\nnumeric\n" << H_num;
  EXPECT_LT((r0 - f(Eigen::Matrix<double, 10, 1>::Zero())).norm(), 1e-12);
}

TEST(GnssPositionModel, ZeroAtTruthAndJacobian) {
  std::mt19937 rng(11);
  const Vec3 lever_b(-0.17, -0.20, 0.3);
  for (int i = 0; i < 10; ++i) {
    const State s = RandomState(rng);
    const Vec3 z_w = s.p_wb + s.q_wb * lever_b;
    EXPECT_LT(GnssPositionModel::Residual<double>(s.p_wb, s.q_wb, lever_b, z_w).norm(), 1e-12);
    CheckJacobian<3>(
        [&](const auto& d) {
          using T = typename std::decay_t<decltype(d)>::Scalar;
          Eigen::Matrix<T, 3, 1> p, v;
          Eigen::Quaternion<T> q;
          T sc;
          Perturb<T>(s, d, &p, &v, &q, &sc);
          return GnssPositionModel::Residual<T>(p, q, lever_b, z_w + Vec3(0.1, -0.2, 0.05));
        },
        1e-7);
  }
}

TEST(HeadingModel, ZeroAtTruthWrapsAndJacobian) {
  std::mt19937 rng(12);
  const double mount = 12.06 * kDegToRad;
  for (int i = 0; i < 10; ++i) {
    const State s = RandomState(rng);
    const Vec3 x_G_w = s.q_wb * Vec3(std::cos(mount), std::sin(mount), 0.0);
    const double yaw_true = std::atan2(x_G_w.y(), x_G_w.x());
    EXPECT_NEAR(HeadingModel::Residual<double>(s.q_wb, mount, yaw_true), 0.0, 1e-12);
    // The same heading one turn away is the same measurement.
    EXPECT_NEAR(HeadingModel::Residual<double>(s.q_wb, mount, yaw_true + 2 * kPi), 0.0, 1e-12);
    EXPECT_NEAR(HeadingModel::Residual<double>(s.q_wb, mount, WrapAngle(yaw_true + 0.1)), -0.1, 1e-9);
    CheckJacobian<1>(
        [&](const auto& d) {
          using T = typename std::decay_t<decltype(d)>::Scalar;
          Eigen::Matrix<T, 3, 1> p, v;
          Eigen::Quaternion<T> q;
          T sc;
          Perturb<T>(s, d, &p, &v, &q, &sc);
          return Eigen::Matrix<T, 1, 1>(HeadingModel::Residual<T>(q, mount, WrapAngle(yaw_true + 0.05)));
        },
        1e-7);
  }
  // Heading against the book's convention: a vehicle facing north (yaw 90°) with the mount angle reads
  // a compass heading of 0° − mount.
  const Quat q_north = QuatFromYaw(kPi / 2);
  EXPECT_NEAR(HeadingModel::Residual<double>(q_north, mount, CompassDegToEnuYaw(-12.06)), 0.0, 1e-12);
}

TEST(WheelModels, ZeroAtTruthAndJacobian) {
  std::mt19937 rng(13);
  for (int i = 0; i < 10; ++i) {
    State s = RandomState(rng);
    const double speed = 7.0;
    s.v_w = s.q_wb * Vec3(speed, 0.0, 0.0);
    EXPECT_NEAR(WheelSpeedModel::Residual<double>(s.q_wb, s.v_w, s.scale, s.scale * speed), 0.0, 1e-12);
    EXPECT_LT(NonHolonomicModel::Residual<double>(s.q_wb, s.v_w).norm(), 1e-12);
    CheckJacobian<1>(
        [&](const auto& d) {
          using T = typename std::decay_t<decltype(d)>::Scalar;
          Eigen::Matrix<T, 3, 1> p, v;
          Eigen::Quaternion<T> q;
          T sc;
          Perturb<T>(s, d, &p, &v, &q, &sc);
          return Eigen::Matrix<T, 1, 1>(WheelSpeedModel::Residual<T>(q, v, sc, 6.5));
        },
        1e-7);
    CheckJacobian<2>(
        [&](const auto& d) {
          using T = typename std::decay_t<decltype(d)>::Scalar;
          Eigen::Matrix<T, 3, 1> p, v;
          Eigen::Quaternion<T> q;
          T sc;
          Perturb<T>(s, d, &p, &v, &q, &sc);
          return NonHolonomicModel::Residual<T>(q, v);
        },
        1e-7);
  }
}

TEST(WheelModels, SpeedFromPulses) {
  // One revolution per second of a 0.155 m wheel.
  EXPECT_NEAR(WheelSpeedFromPulses(102.4, 0.155, 1024, 0.1), 2 * kPi * 0.155, 1e-12);
}

}  // namespace
}  // namespace gins
