// Wheel-yaw factor: the turn between keyframes i and j from the left/right wheel difference
// (core/odometry_model.h), a yaw-rate aid for the gyro.
//
// Parameter blocks: pose_i (7), pose_j (7) (factors/pose_manifold.h), scale_i (1).
// Residual (1):
//   r = (s·(Log(R_iᵀ·R_j)).z − Δψ) / σ        (unitless; Δψ and σ in rad)
// The raw residual is WheelYawModel::Residual.
#pragma once

#include <ceres/cost_function.h>

#include "core/conventions.h"
#include "core/odometry_model.h"
#include "factors/pose_manifold.h"

namespace gins {

class WheelYawFactor {
 public:
  static constexpr int kResidualDim = WheelYawModel::kResidualDim;

  WheelYawFactor(double yaw_change, double sigma) : yaw_change_(yaw_change), inv_sigma_(1.0 / sigma) {}

  template <typename T>
  bool operator()(const T* pose_i, const T* pose_j, const T* scale_i, T* residual) const {
    residual[0] = WheelYawModel::Residual<T>(Eigen::Quaternion<T>(PoseRotation(pose_i)),
                                             Eigen::Quaternion<T>(PoseRotation(pose_j)), scale_i[0], yaw_change_) *
                  T(inv_sigma_);
    return true;
  }

  // AutoDiffCostFunction<WheelYawFactor, 1, 7, 7, 1>.
  static ceres::CostFunction* Create(double yaw_change, double sigma);

 private:
  double yaw_change_, inv_sigma_;
};

}  // namespace gins
