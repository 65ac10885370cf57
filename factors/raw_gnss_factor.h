// An epoch's raw GNSS observations in the smoother: its pseudoranges (or range rates), the receiver clocks
// eliminated by differences, as the constraint they put on the antenna's position (velocity) in w
// (core/gnss_raw.h, CompressRows): r = S·(p_ant − z) with S the rows' square-root information, 3×3 and of
// rank 1-3 (two satellites of one system constrain one direction). So a satellite counts as soon as it is
// seen, where a single-point fix needs four or more.
//
//   RawRangeAtTime  r = S·(p_t + R_t·lever_b − z_w)                        (3, core/gnss_model.h's residual)
//   RawRateAtTime   r = S·(v_t + R_t·(ω_b × lever_b) − z_w)                (3, core/gnss_velocity_model.h's)
//
// At its own time through the IMU preintegrated from a keyframe: PreintAttachedFactor<RawRangeAtTime>
// (factors/preint_attached_factor.h); at a keyframe's time: RawAtKeyframeFactor, on pose (7) and vel (3).
//
// The carrier phases' time differences between two epochs at keyframes i and j (core/gnss_raw.h,
// PhaseRangeChange), the clock's change differenced out, constrain the antenna's displacement the same way:
//   RawDisplacementFactor  r = S·((p_j + R_j·lever_b) − (p_i + R_i·lever_b) − d_w)   (3; pose_i, pose_j)
#pragma once

#include <ceres/cost_function.h>

#include <utility>

#include "core/conventions.h"
#include "factors/preint_attached_factor.h"

namespace gins {

// Model M (its σ one) whitened by a full square-root information S instead of a σ per axis.
template <class M>
struct SqrtInfoWhitened {
  static constexpr int kResidualDim = 3;
  M model;
  Mat3 sqrt_info;
  template <typename T>
  void operator()(const PredictedKinematics<T>& k, T* residual) const {
    Eigen::Matrix<T, 3, 1> r;
    model(k, r.data());
    Eigen::Map<Eigen::Matrix<T, 3, 1>> out(residual);
    out = sqrt_info.cast<T>() * r;
  }
  Eigen::Matrix<double, 3, 9> Linearize(const PredictedKinematics<double>& k, double* residual) const {
    Vec3 r;
    const Eigen::Matrix<double, 3, 9> J = model.Linearize(k, r.data());
    Eigen::Map<Vec3> out(residual);
    out = sqrt_info * r;
    return sqrt_info * J;
  }
};

using RawRangeAtTime = SqrtInfoWhitened<GnssAtTime>;          // model: GnssAtTime{z_w, ones, lever_b}
using RawRateAtTime = SqrtInfoWhitened<GnssVelocityAtTime>;   // model: GnssVelocityAtTime{z_w, ones, ω_b, lever_b}

// M at a keyframe's own state: pose (7) and velocity (3).
template <class M>
class RawAtKeyframeFactor {
 public:
  explicit RawAtKeyframeFactor(M model) : model_(std::move(model)) {}

  template <typename T>
  bool operator()(const T* pose, const T* vel, T* residual) const {
    using Vec3T = Eigen::Matrix<T, 3, 1>;
    model_(PredictedKinematics<T>{Vec3T(PosePosition(pose)), Vec3T(Eigen::Map<const Vec3T>(vel)),
                                  Eigen::Quaternion<T>(PoseRotation(pose))},
           residual);
    return true;
  }

  // AutoDiffCostFunction<RawAtKeyframeFactor, 3, 7, 3>.
  static ceres::CostFunction* Create(M model);

 private:
  M model_;
};

class RawDisplacementFactor {
 public:
  RawDisplacementFactor(const Vec3& d_w, const Mat3& sqrt_info, const Vec3& lever_b)
      : d_w_(d_w), sqrt_info_(sqrt_info), lever_b_(lever_b) {}

  template <typename T>
  bool operator()(const T* pose_i, const T* pose_j, T* residual) const {
    using Vec3T = Eigen::Matrix<T, 3, 1>;
    const Vec3T lever = lever_b_.cast<T>();
    const Vec3T d = (PosePosition(pose_j) + PoseRotation(pose_j) * lever) -
                    (PosePosition(pose_i) + PoseRotation(pose_i) * lever) - d_w_.cast<T>();
    Eigen::Map<Vec3T> out(residual);
    out = sqrt_info_.cast<T>() * d;
    return true;
  }

  // AutoDiffCostFunction<RawDisplacementFactor, 3, 7, 7>.
  static ceres::CostFunction* Create(const Vec3& d_w, const Mat3& sqrt_info, const Vec3& lever_b);

 private:
  Vec3 d_w_;
  Mat3 sqrt_info_;
  Vec3 lever_b_;
};

}  // namespace gins
