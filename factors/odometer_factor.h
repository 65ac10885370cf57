// Odometer factor: every encoder record between keyframes i and j, integrated (core/odometry_model.h).
//
// Parameter blocks: pose_i (7), pose_j (7) (factors/pose_manifold.h), scale_i (1: odometer scale s).
// Residual (1):
//   r = (s·uᵀ·R_iᵀ·(a_j − a_i) − |D_i|) / σ      (unitless; a = rear-axle centre, D_i the encoders'
//                                                   displacement in the body frame at i, u its direction)
// The raw residual is OdometerModel::Residual.
#pragma once

#include <ceres/cost_function.h>

#include "core/conventions.h"
#include "core/odometry_model.h"
#include "factors/pose_manifold.h"

namespace gins {

class OdometerFactor {
 public:
  static constexpr int kResidualDim = OdometerModel::kResidualDim;

  // displacement_i: D_i (m, body frame at i); sigma: 1-σ of |D_i| (m, > 0); lever_b: rear-axle centre in b.
  OdometerFactor(const Vec3& displacement_i, double sigma, const Vec3& lever_b)
      : distance_(displacement_i.norm()),
        u_i_(distance_ > 1e-9 ? Vec3(displacement_i / distance_) : Vec3::UnitX()),
        inv_sigma_(1.0 / sigma),
        lever_b_(lever_b) {}

  template <typename T>
  bool operator()(const T* pose_i, const T* pose_j, const T* scale_i, T* residual) const {
    residual[0] = OdometerModel::Residual<T>(Eigen::Matrix<T, 3, 1>(PosePosition(pose_i)),
                                             Eigen::Quaternion<T>(PoseRotation(pose_i)),
                                             Eigen::Matrix<T, 3, 1>(PosePosition(pose_j)),
                                             Eigen::Quaternion<T>(PoseRotation(pose_j)), scale_i[0], lever_b_, u_i_,
                                             distance_) *
                  T(inv_sigma_);
    return true;
  }

  // AutoDiffCostFunction<OdometerFactor, 1, 7, 7, 1>.
  static ceres::CostFunction* Create(const Vec3& displacement_i, double sigma, const Vec3& lever_b);

 private:
  double distance_;
  Vec3 u_i_;
  double inv_sigma_;
  Vec3 lever_b_;
};

}  // namespace gins
