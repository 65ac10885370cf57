// Non-holonomic constraint factor: a wheeled vehicle does not slide sideways or jump.
//
// Parameter blocks: pose (7: p_wb, q_wb x y z w — factors/pose_manifold.h), vel (3: v_w, m/s).
// Residual (2), at the rear-axle centre lever_b with the body rate ω_b (zero: the body origin):
//   r = (v_a.y, v_a.z) / σ,   v_a = R_wbᵀ·v_w + ω_b × lever_b      (unitless; raw residual and σ in m/s)
// The raw residual is AxleNhcModel::Residual (core/wheel_model.h), shared with the ESKF.
#pragma once

#include <ceres/cost_function.h>

#include "core/conventions.h"
#include "core/wheel_model.h"
#include "factors/pose_manifold.h"

namespace gins {

class NhcFactor {
 public:
  static constexpr int kResidualDim = AxleNhcModel::kResidualDim;

  // sigma: 1-σ of the lateral and vertical speed (m/s, > 0); omega_b (rad/s) and lever_b (m) as above.
  explicit NhcFactor(double sigma, const Vec3& omega_b = Vec3::Zero(), const Vec3& lever_b = Vec3::Zero())
      : inv_sigma_(1.0 / sigma), omega_b_(omega_b), lever_b_(lever_b) {}

  template <typename T>
  bool operator()(const T* pose, const T* vel, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> v_w(vel);
    Eigen::Map<Eigen::Matrix<T, 2, 1>> residual_out(residual);
    residual_out =
        AxleNhcModel::Residual<T>(Eigen::Quaternion<T>(PoseRotation(pose)), v_w, omega_b_, lever_b_) * T(inv_sigma_);
    return true;
  }

  // AutoDiffCostFunction<NhcFactor, 2, 7, 3>.
  static ceres::CostFunction* Create(double sigma, const Vec3& omega_b = Vec3::Zero(),
                                     const Vec3& lever_b = Vec3::Zero());

 private:
  double inv_sigma_;
  Vec3 omega_b_, lever_b_;
};

}  // namespace gins
