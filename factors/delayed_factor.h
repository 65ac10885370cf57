// GNSS measurements stamped td after they were made (gnss.time_offset_s: estimate), on the keyframe's
// time-offset block: the measurement's model at the state at t − td, taken back from the state at the stamp t
// through the acceleration a_w and body rate ω_b there (core/time_shift.h: second order in td).
//
//   DelayedAtKeyframeFactor<M>     the stamp at keyframe i's time (DelayedAtKeyframeCostFunction).
//                                  Blocks: pose_i (7), vel_i (3), td_i (1).
//   DelayedAttachedCostFunction<M> the stamp between keyframe i and the next: the state at t from the IMU
//                                  preintegrated from t_i (PreintAttachedCostFunction's prediction and
//                                  analytic Jacobians). Blocks: pose_i (7), vel_i (3), bias_i (6), td_i (1).
// Residual: M's (GnssAtTime, HeadingAtTime, GnssVelocityAtTime: factors/preint_attached_factor.h), whitened by it.
// td in s, beyond the stated gnss.time_offset_s (the session re-stamps the records by that).
#pragma once

#include <ceres/cost_function.h>
#include <ceres/sized_cost_function.h>

#include <memory>
#include <utility>

#include "core/time_shift.h"
#include "factors/preint_attached_factor.h"

namespace gins {

template <class Measurement>
struct Delayed {
  static constexpr int kResidualDim = Measurement::kResidualDim;
  Measurement measurement;
  Vec3 a_w, omega_b;  // at the stamp, held over td
  template <typename T>
  void operator()(const PredictedKinematics<T>& k, const T& td, T* residual) const {
    const ShiftedKinematics<T> s = ShiftBack<T>(k.p, k.v, k.q, a_w, omega_b, td);
    measurement(PredictedKinematics<T>{s.p_wb, s.v_w, s.q_wb}, residual);
  }
};

template <class Measurement>
class DelayedAtKeyframeFactor {
 public:
  static constexpr int kResidualDim = Measurement::kResidualDim;

  explicit DelayedAtKeyframeFactor(Delayed<Measurement> delayed) : delayed_(std::move(delayed)) {}

  template <typename T>
  bool operator()(const T* pose, const T* vel, const T* td, T* residual) const {
    using Vec3T = Eigen::Matrix<T, 3, 1>;
    const PredictedKinematics<T> k{Vec3T(PosePosition(pose)), Vec3T(Eigen::Map<const Vec3T>(vel)),
                                   Eigen::Quaternion<T>(PoseRotation(pose))};
    delayed_(k, td[0], residual);
    return true;
  }

  // The production cost function: DelayedAtKeyframeCostFunction (the model's Linearize and the shift's
  // Jacobian in the tangent, lifted to the ambient pose).
  static ceres::CostFunction* Create(Delayed<Measurement> delayed);
  // AutoDiffCostFunction<DelayedAtKeyframeFactor, kResidualDim, 7, 3, 1> of the same residual: the test oracle.
  static ceres::CostFunction* CreateAutoDiff(Delayed<Measurement> delayed);

  const Delayed<Measurement>& delayed() const { return delayed_; }

 private:
  Delayed<Measurement> delayed_;
};

template <class Measurement>
class DelayedAtKeyframeCostFunction final
    : public ceres::SizedCostFunction<Measurement::kResidualDim, pose::kAmbient, 3, 1> {
 public:
  explicit DelayedAtKeyframeCostFunction(Delayed<Measurement> delayed) : factor_(std::move(delayed)) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  DelayedAtKeyframeFactor<Measurement> factor_;
};

template <class Measurement>
class DelayedAttachedCostFunction final
    : public ceres::SizedCostFunction<Measurement::kResidualDim, pose::kAmbient, 3, 6, 1> {
 public:
  // Requires a non-empty preintegration (as PreintAttachedFactor::Create).
  DelayedAttachedCostFunction(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth,
                              Delayed<Measurement> delayed)
      : factor_(std::move(preint), earth, delayed.measurement), a_w_(delayed.a_w), omega_b_(delayed.omega_b) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  static ceres::CostFunction* Create(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth,
                                     Delayed<Measurement> delayed);
  // Autodiff of the same residual through PredictKinematics: the test oracle.
  static ceres::CostFunction* CreateAutoDiff(std::shared_ptr<const Preintegration> preint,
                                             const ImuEarthTerms& earth, Delayed<Measurement> delayed);

 private:
  PreintAttachedFactor<Measurement> factor_;
  Vec3 a_w_, omega_b_;
};

}  // namespace gins
