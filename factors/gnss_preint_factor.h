// GNSS fix at its own time t, between keyframes i and the next: attached to keyframe i through the IMU
// preintegrated from t_i to t (so keyframe placement never costs a fix).
//
// Parameter blocks: pose_i (7: p_wb, q_wb x y z w — factors/pose_manifold.h), vel_i (3), bias_i (6).
// Residual (3, world ENU axes), per axis divided by the fix's 1-σ:
//   r = (p_t + R_t·lever_b − z_w) ./ σ_w      with (p_t, R_t) = PredictKinematics(Δ_i→t, state i)
// (core/preintegration.h, bias-corrected to first order, Earth terms included). The raw residual is
// GnssPositionModel::Residual (core/gnss_model.h), as for a fix at a keyframe.
#pragma once

#include <ceres/cost_function.h>

#include <memory>
#include <utility>

#include "core/conventions.h"
#include "core/gnss_model.h"
#include "core/preintegration.h"
#include "factors/pose_manifold.h"

namespace gins {

class GnssPreintFactor {
 public:
  static constexpr int kResidualDim = GnssPositionModel::kResidualDim;

  GnssPreintFactor(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth, const Vec3& z_w,
                   const Vec3& sigma_w, const Vec3& lever_b)
      : preint_(std::move(preint)),
        earth_(earth),
        turns_(earth, preint_->dt()),
        z_w_(z_w),
        inv_sigma_(sigma_w.cwiseInverse()),
        lever_b_(lever_b) {}

  template <typename T>
  bool operator()(const T* pose_i, const T* vel_i, const T* bias_i, T* residual) const {
    using Vec3T = Eigen::Matrix<T, 3, 1>;
    const PredictedKinematics<T> k = PredictKinematics<T>(
        *preint_, earth_, turns_, Vec3T(PosePosition(pose_i)), Eigen::Quaternion<T>(PoseRotation(pose_i)),
        Eigen::Map<const Vec3T>(vel_i), Eigen::Map<const Vec3T>(bias_i), Eigen::Map<const Vec3T>(bias_i + 3));
    Eigen::Map<Vec3T> out(residual);
    out = GnssPositionModel::Residual<T>(k.p, k.q, lever_b_, z_w_).cwiseProduct(inv_sigma_.cast<T>());
    return true;
  }

  // AutoDiffCostFunction<GnssPreintFactor, 3, 7, 3, 6>. Requires σ > 0 and a non-empty preintegration.
  static ceres::CostFunction* Create(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth,
                                     const Vec3& z_w, const Vec3& sigma_w, const Vec3& lever_b);

 private:
  std::shared_ptr<const Preintegration> preint_;
  ImuEarthTerms earth_;
  EarthTurns turns_;
  Vec3 z_w_, inv_sigma_, lever_b_;
};

}  // namespace gins
