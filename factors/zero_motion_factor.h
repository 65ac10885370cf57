// Zero-motion factor between two keyframes i and j of one standstill: the vehicle neither moved nor turned.
//
// Parameter blocks: pose_i (7), pose_j (7) (factors/pose_manifold.h).
// Residual (6):
//   r = [ (p_j − p_i) / σ_p ;  Log(q_iᵀ·q_j) / σ_θ ]     (unitless; σ_p in m, σ_θ in rad)
// The rotation part is the zero-rotation constraint: with the IMU factor between the same keyframes it
// observes the gyro bias (the preintegrated ΔR must be the identity). Together with the zero-velocity
// factors it keeps a parked vehicle from wandering. σ_θ = ∞ leaves the rotation free (a vehicle turning in
// place: its rotation residual is then zero).
#pragma once

#include <ceres/cost_function.h>

#include "core/conventions.h"
#include "core/so3.h"
#include "factors/pose_manifold.h"

namespace gins {

class ZeroMotionFactor {
 public:
  static constexpr int kResidualDim = 6;

  ZeroMotionFactor(double sigma_p, double sigma_theta) : inv_sigma_p_(1.0 / sigma_p), inv_sigma_theta_(1.0 / sigma_theta) {}

  template <typename T>
  bool operator()(const T* pose_i, const T* pose_j, T* residual) const {
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r.template head<3>() = (PosePosition(pose_j) - PosePosition(pose_i)) * T(inv_sigma_p_);
    const Eigen::Quaternion<T> q_i(PoseRotation(pose_i)), q_j(PoseRotation(pose_j));
    r.template tail<3>() = LogQuat<T>(q_i.conjugate() * q_j) * T(inv_sigma_theta_);
    return true;
  }

  // AutoDiffCostFunction<ZeroMotionFactor, 6, 7, 7>.
  static ceres::CostFunction* Create(double sigma_p, double sigma_theta);

 private:
  double inv_sigma_p_, inv_sigma_theta_;
};

}  // namespace gins
