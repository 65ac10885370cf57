// A measurement at its own time t, between keyframe i and the next, attached to keyframe i through the IMU
// preintegrated from t_i to t: the state at t is PredictKinematics(Δ_i→t, state i) (core/preintegration.h:
// bias-corrected to first order, Earth terms included), and the measurement's model takes it from there.
// So keyframe placement never costs a measurement (a 10 Hz receiver with keyframes every 0.5-1 s).
//
// Parameter blocks: pose_i (7: p_wb, q_wb x y z w — factors/pose_manifold.h), vel_i (3), bias_i (6).
// Residual: the model's, whitened by it. Models (each delegates to its core model):
//   GnssAtTime     r = (p_t + R_t·lever_b − z_w) ./ σ_w                     (3, core/gnss_model.h)
//   HeadingAtTime  r = wrap(yaw(R_t·Rz(mount)) − yaw_meas) / σ              (1, core/heading_model.h)
//   GnssVelocityAtTime     r = (v_t + R_t·(ω_b × lever_b) − z_w) ./ σ_w             (3, core/gnss_velocity_model.h)
#pragma once

#include <ceres/cost_function.h>
#include <ceres/sized_cost_function.h>

#include <cmath>
#include <memory>
#include <utility>

#include "core/conventions.h"
#include "core/gnss_model.h"
#include "core/gnss_velocity_model.h"
#include "core/heading_model.h"
#include "core/preintegration.h"
#include "core/so3.h"
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
  // The residual and its Jacobian in the right-perturbed (δp, δθ, δv): d(R·Exp(δθ)·l) = −R·[l]×·δθ.
  Eigen::Matrix<double, 3, 9> Linearize(const PredictedKinematics<double>& k, double* residual) const {
    operator()(k, residual);
    Eigen::Matrix<double, 3, 9> J = Eigen::Matrix<double, 3, 9>::Zero();
    J.leftCols<3>() = inv_sigma.asDiagonal();
    J.middleCols<3>(3) = inv_sigma.asDiagonal() * (k.q.toRotationMatrix() * Hat<double>(-lever_b));
    return J;
  }
};

struct HeadingAtTime {
  static constexpr int kResidualDim = HeadingModel::kResidualDim;
  double yaw_meas, inv_sigma, mount_yaw;
  template <typename T>
  void operator()(const PredictedKinematics<T>& k, T* residual) const {
    residual[0] = HeadingModel::Residual<T>(k.q, mount_yaw, yaw_meas) * T(inv_sigma);
  }
  // The same, with its Jacobian: with x = R·x_G (the antenna axis in w), d atan2(x_y, x_x) = (x_x·dx_y −
  // x_y·dx_x) / (x_x² + x_y²) and dx = −R·[x_G]×·δθ (the wrap is a constant).
  Eigen::Matrix<double, 1, 9> Linearize(const PredictedKinematics<double>& k, double* residual) const {
    operator()(k, residual);
    const Mat3 R = k.q.toRotationMatrix();
    const Vec3 x_G_b(std::cos(mount_yaw), std::sin(mount_yaw), 0.0);
    const Vec3 x = R * x_G_b;
    const Eigen::RowVector3d d_yaw_d_x = Eigen::RowVector3d(-x.y(), x.x(), 0.0) / (x.x() * x.x() + x.y() * x.y());
    Eigen::Matrix<double, 1, 9> J = Eigen::Matrix<double, 1, 9>::Zero();
    J.middleCols<3>(3) = -inv_sigma * d_yaw_d_x * R * Hat<double>(x_G_b);
    return J;
  }
};

struct GnssVelocityAtTime {
  static constexpr int kResidualDim = GnssVelocityModel::kResidualDim;
  Vec3 z_w, inv_sigma, omega_b, lever_b;
  template <typename T>
  void operator()(const PredictedKinematics<T>& k, T* residual) const {
    Eigen::Map<Eigen::Matrix<T, 3, 1>> out(residual);
    out = GnssVelocityModel::Residual<T>(k.q, k.v, omega_b, lever_b, z_w).cwiseProduct(inv_sigma.cast<T>());
  }
  // The same, with its Jacobian (as GnssAtTime's, with ω_b × lever_b for the lever and δv for δp).
  Eigen::Matrix<double, 3, 9> Linearize(const PredictedKinematics<double>& k, double* residual) const {
    operator()(k, residual);
    Eigen::Matrix<double, 3, 9> J = Eigen::Matrix<double, 3, 9>::Zero();
    J.middleCols<3>(3) = inv_sigma.asDiagonal() * (k.q.toRotationMatrix() * Hat<double>(lever_b.cross(omega_b)));
    J.rightCols<3>() = inv_sigma.asDiagonal();
    return J;
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

  // The production cost function: PreintAttachedCostFunction (analytic prediction Jacobians). Requires a
  // non-empty preintegration and σ > 0 (the measurement's inverse σ finite).
  static ceres::CostFunction* Create(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth,
                                     Measurement measurement);
  // AutoDiffCostFunction<PreintAttachedFactor, kResidualDim, 7, 3, 6> of the same residual: the test oracle.
  static ceres::CostFunction* CreateAutoDiff(std::shared_ptr<const Preintegration> preint,
                                             const ImuEarthTerms& earth, Measurement measurement);

  const Preintegration& preintegration() const { return *preint_; }
  const ImuEarthTerms& earth() const { return earth_; }
  const EarthTurns& turns() const { return turns_; }
  const Measurement& measurement() const { return measurement_; }

 private:
  std::shared_ptr<const Preintegration> preint_;
  ImuEarthTerms earth_;
  EarthTurns turns_;
  Measurement measurement_;
};

// PreintAttachedFactor with analytic Jacobians of the prediction: the state at t as a function of state i and
// its biases (core/preintegration.h: PredictKinematics), 9×15 in closed form in the right-perturbed tangents,
//   δp_t = δp_i + A·T·δv_i − A·E3ᵀ·R_i·[Δp]×·δθ_i + A·E3ᵀ·R_i·(∂Δp/∂b)·δb
//   δθ_t = ΔRᵀ·δθ_i + Jr(φ)·(∂ΔR/∂bg)·δbg
//   δv_t = δv_i − E2ᵀ·R_i·[Δv]×·δθ_i + E2ᵀ·R_i·(∂Δv/∂b)·δb − 2[ω]×·(δp_t − δp_i)
// (A = (I + [ω]×T)⁻¹, E_k the Earth's turns; identities for the flat Earth), times the measurement's own
// Jacobian in (δp_t, δθ_t, δv_t), its Linearize (closed form).
// The pose block's tangent Jacobian is lifted to the ambient one as ImuCostFunction does.
template <class Measurement>
class PreintAttachedCostFunction final
    : public ceres::SizedCostFunction<Measurement::kResidualDim, pose::kAmbient, 3, 6> {
 public:
  PreintAttachedCostFunction(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth,
                             Measurement measurement)
      : factor_(std::move(preint), earth, std::move(measurement)) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  const PreintAttachedFactor<Measurement>& factor() const { return factor_; }

 private:
  PreintAttachedFactor<Measurement> factor_;
};

}  // namespace gins
