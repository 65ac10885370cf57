#include "factors/pose_manifold.h"

#include "core/so3.h"

namespace gins {

namespace {

using Mat76 = Eigen::Matrix<double, 7, 6, Eigen::RowMajor>;
using Mat67 = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;
using Mat34 = Eigen::Matrix<double, 3, 4>;

}  // namespace

Mat34 QuaternionLift(const Quat& q) {
  Mat34 M;
  M.leftCols<3>() = 2.0 * (q.w() * Mat3::Identity() - Hat<double>(q.vec()));
  M.col(3) = -2.0 * q.vec();
  return M;
}

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Vec3> p(x + pose::kP);
  const Eigen::Map<const Quat> q(x + pose::kQ);
  const Eigen::Map<const Vec3> dp(delta + pose::kP);
  const Eigen::Map<const Vec3> dtheta(delta + pose::kTheta);
  Eigen::Map<Vec3>(x_plus_delta + pose::kP) = p + dp;
  Eigen::Map<Quat>(x_plus_delta + pose::kQ) = (q * ExpQuat<double>(dtheta)).normalized();
  return true;
}

bool PoseManifold::PlusJacobian(const double* x, double* jacobian) const {
  const Eigen::Map<const Quat> q(x + pose::kQ);
  Eigen::Map<Mat76> J(jacobian);
  J.setZero();
  J.block<3, 3>(pose::kP, pose::kP).setIdentity();
  // d(q ⊗ (δθ/2, 1))/dδθ: vector part ½(w·I + [v]×), scalar part −½vᵀ.
  J.block<3, 3>(pose::kQ, pose::kTheta) = 0.5 * (q.w() * Mat3::Identity() + Hat<double>(q.vec()));
  J.block<1, 3>(pose::kQ + 3, pose::kTheta) = -0.5 * q.vec().transpose();
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Map<const Quat> q_x(x + pose::kQ);
  const Eigen::Map<const Quat> q_y(y + pose::kQ);
  Eigen::Map<Vec3>(y_minus_x + pose::kP) =
      Eigen::Map<const Vec3>(y + pose::kP) - Eigen::Map<const Vec3>(x + pose::kP);
  Eigen::Map<Vec3>(y_minus_x + pose::kTheta) = LogQuat<double>(q_x.conjugate() * q_y);
  return true;
}

bool PoseManifold::MinusJacobian(const double* x, double* jacobian) const {
  MinusJacobianAt(x, x, jacobian);
  return true;
}

void PoseManifold::MinusJacobianAt(const double* y, const double* x, double* jacobian) {
  const Eigen::Map<const Quat> q_x(x + pose::kQ);
  const Eigen::Map<const Quat> q_y(y + pose::kQ);
  Eigen::Map<Mat67> J(jacobian);
  J.setZero();
  J.block<3, 3>(pose::kP, pose::kP).setIdentity();
  const Vec3 phi = LogQuat<double>(q_x.conjugate() * q_y);
  // Log(q_x⁻¹·q_y·Exp(δ)) = φ + Jr⁻¹(φ)·δ, and M(q_y) turns an ambient change of q_y into that δ.
  J.block<3, 4>(pose::kTheta, pose::kQ) = RightJacobianInverse(phi) * QuaternionLift(Quat(q_y));
}

}  // namespace gins
