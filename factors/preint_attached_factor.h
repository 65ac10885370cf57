// A measurement at its own time t, between keyframe i and the next, attached to keyframe i through the IMU
// preintegrated from t_i to t: the state at t is PredictKinematics(Δ_i→t, state i) (core/preintegration.h:
// bias-corrected to first order, Earth terms included), and the measurement's model takes it from there.
// So keyframe placement never costs a measurement (a 10 Hz receiver with keyframes every 0.5-1 s).
//
// Parameter blocks: pose_i (7: p_wb, q_wb x y z w — factors/pose_manifold.h), vel_i (3), bias_i (6).
// Residual: the model's, whitened by it. Models (each delegates to its core model):
//   GnssAtTime     r = (p_t + R_t·lever_b − z_w) ./ σ_w                     (3, core/gnss_model.h)
//   HeadingAtTime  r = wrap(yaw(R_t·Rz(mount)) − yaw_meas) / σ              (1, core/heading_model.h)
//   GvelAtTime     r = (v_t + R_t·(ω_b × lever_b) − z_w) ./ σ_w             (3, core/gvel_model.h)
#pragma once

#include <ceres/cost_function.h>

#include <memory>
#include <utility>

#include "core/conventions.h"
#include "core/gnss_model.h"
#include "core/gvel_model.h"
#include "core/heading_model.h"
#include "core/preintegration.h"
#include "factors/pose_manifold.h"

namespace gins {

struct GnssAtTime {
  static constexpr int kResidualDim = GnssPositionModel::kResidualDim;
  Vec3 z_w, inv_sigma, lever_b;
  template <typename T>
  void operator()(const PredictedKinematics<T>& k, T* residual) const {
    Eigen::Map<Eigen::Matrix<T, 3, 1>> out(residual);
    out = GnssPositionModel::Residual<T>(k.p, k.q, lever_b, z_w).cwiseProduct(inv_sigma.cast<T>());
  }
};

struct HeadingAtTime {
  static constexpr int kResidualDim = HeadingModel::kResidualDim;
  double yaw_meas, inv_sigma, mount_yaw;
  template <typename T>
  void operator()(const PredictedKinematics<T>& k, T* residual) const {
    residual[0] = HeadingModel::Residual<T>(k.q, mount_yaw, yaw_meas) * T(inv_sigma);
  }
};

struct GvelAtTime {
  static constexpr int kResidualDim = GnssVelocityModel::kResidualDim;
  Vec3 z_w, inv_sigma, omega_b, lever_b;
  template <typename T>
  void operator()(const PredictedKinematics<T>& k, T* residual) const {
    Eigen::Map<Eigen::Matrix<T, 3, 1>> out(residual);
    out = GnssVelocityModel::Residual<T>(k.q, k.v, omega_b, lever_b, z_w).cwiseProduct(inv_sigma.cast<T>());
  }
};

template <class Measurement>
class PreintAttachedFactor {
 public:
  static constexpr int kResidualDim = Measurement::kResidualDim;

  PreintAttachedFactor(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth,
                       Measurement measurement)
      : preint_(std::move(preint)),
        earth_(earth),
        turns_(earth, preint_->dt()),
        measurement_(std::move(measurement)) {}

  template <typename T>
  bool operator()(const T* pose_i, const T* vel_i, const T* bias_i, T* residual) const {
    using Vec3T = Eigen::Matrix<T, 3, 1>;
    const PredictedKinematics<T> k = PredictKinematics<T>(
        *preint_, earth_, turns_, Vec3T(PosePosition(pose_i)), Eigen::Quaternion<T>(PoseRotation(pose_i)),
        Eigen::Map<const Vec3T>(vel_i), Eigen::Map<const Vec3T>(bias_i), Eigen::Map<const Vec3T>(bias_i + 3));
    measurement_(k, residual);
    return true;
  }

  // AutoDiffCostFunction<PreintAttachedFactor, kResidualDim, 7, 3, 6> (factors/factories.cc). Requires a
  // non-empty preintegration and σ > 0 (the measurement's inverse σ finite).
  static ceres::CostFunction* Create(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth,
                                     Measurement measurement);

 private:
  std::shared_ptr<const Preintegration> preint_;
  ImuEarthTerms earth_;
  EarthTurns turns_;
  Measurement measurement_;
};

}  // namespace gins
