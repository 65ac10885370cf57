// GNSS (Doppler) velocity factor at a keyframe.
//
// Parameter blocks: pose (7: p_wb, q_wb x y z w — factors/pose_manifold.h), vel (3: v_w, m/s).
// Residual (3, world ENU axes), per axis divided by the measurement's 1-σ:
//   r = (v_w + R_wb·(ω_b × lever_b) − z_w) ./ σ_w      (unitless; raw residual and σ in m/s)
// The raw residual is GnssVelocityModel::Residual (core/gnss_velocity_model.h), shared with the ESKF.
#pragma once

#include <ceres/cost_function.h>

#include "core/conventions.h"
#include "core/gnss_velocity_model.h"
#include "factors/pose_manifold.h"

namespace gins {

class GnssVelocityFactor {
 public:
  static constexpr int kResidualDim = GnssVelocityModel::kResidualDim;

  // z_w: antenna velocity in w (m/s); sigma_w (m/s, > 0); omega_b: body rate (rad/s); lever_b: antenna in b.
  GnssVelocityFactor(const Vec3& z_w, const Vec3& sigma_w, const Vec3& omega_b, const Vec3& lever_b)
      : z_w_(z_w), inv_sigma_(sigma_w.cwiseInverse()), omega_b_(omega_b), lever_b_(lever_b) {}

  template <typename T>
  bool operator()(const T* pose, const T* vel, T* residual) const {
    Eigen::Map<Eigen::Matrix<T, 3, 1>> out(residual);
    out = GnssVelocityModel::Residual<T>(Eigen::Quaternion<T>(PoseRotation(pose)),
                                         Eigen::Map<const Eigen::Matrix<T, 3, 1>>(vel), omega_b_, lever_b_, z_w_)
              .cwiseProduct(inv_sigma_.cast<T>());
    return true;
  }

  // AutoDiffCostFunction<GnssVelocityFactor, 3, 7, 3>.
  static ceres::CostFunction* Create(const Vec3& z_w, const Vec3& sigma_w, const Vec3& omega_b, const Vec3& lever_b);

 private:
  Vec3 z_w_, inv_sigma_, omega_b_, lever_b_;
};

}  // namespace gins
