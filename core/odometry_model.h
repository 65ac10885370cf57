// The vehicle's motion between two keyframes i and j, as the wheels and the non-holonomic constraint see it
// (the smoother's odometer, chord and wheel-yaw factors; the ESKF uses the instantaneous forms of
// core/wheel_model.h at every record). a = p_wb + R_wb·lever_b is the rear-axle centre (core/wheel_model.h).
//
// Odometer: the encoders' displacement over the interval, D_i = Σ_k ΔR_ik·e_x·d_k in the body frame at i (d_k
// the distance of record k, ΔR_ik the preintegrated rotation at its middle), against the axle's
// displacement in that frame, along D's direction u (e_x when the vehicle stood):
//   r_odo = s·uᵀ·R_iᵀ·(a_j − a_i) − |D_i|                       (m; 1)
// Chord (the non-holonomic constraint between keyframes): driving on an arc of constant curvature and
// grade, the axle's chord points along the body x axis halfway between i and j, R_m = R_i·Exp(½·Log(R_iᵀR_j)):
//   r_chord = ((R_mᵀ·(a_j − a_i)).y, (R_mᵀ·(a_j − a_i)).z) / Δt    (m/s, a mean lateral and vertical speed; 2)
// Wheel yaw: the turn about body z from the two wheels' speed difference, Δψ = Σ_k (d_right − d_left)_k / track:
//   r_yaw = s·(Log(R_iᵀ·R_j)).z − Δψ                               (rad; 1)
#pragma once

#include "core/conventions.h"
#include "core/so3.h"

namespace gins {

template <typename T>
Eigen::Matrix<T, 3, 1> AxlePoint(const Eigen::Matrix<T, 3, 1>& p_wb, const Eigen::Quaternion<T>& q_wb,
                                 const Vec3& lever_b) {
  return p_wb + q_wb * lever_b.cast<T>();
}

struct OdometerModel {
  static constexpr int kResidualDim = 1;
  // u_i: unit direction of the encoders' displacement in the body frame at i; distance = |D_i| (m).
  template <typename T>
  static T Residual(const Eigen::Matrix<T, 3, 1>& p_i, const Eigen::Quaternion<T>& q_i,
                    const Eigen::Matrix<T, 3, 1>& p_j, const Eigen::Quaternion<T>& q_j, const T& scale,
                    const Vec3& lever_b, const Vec3& u_i, double distance) {
    const Eigen::Matrix<T, 3, 1> da = AxlePoint<T>(p_j, q_j, lever_b) - AxlePoint<T>(p_i, q_i, lever_b);
    return scale * u_i.cast<T>().dot(q_i.conjugate() * da) - T(distance);
  }
};

struct ChordModel {
  static constexpr int kResidualDim = 2;
  template <typename T>
  static Eigen::Matrix<T, 2, 1> Residual(const Eigen::Matrix<T, 3, 1>& p_i, const Eigen::Quaternion<T>& q_i,
                                         const Eigen::Matrix<T, 3, 1>& p_j, const Eigen::Quaternion<T>& q_j,
                                         const Vec3& lever_b, double dt) {
    const Eigen::Matrix<T, 3, 1> half = T(0.5) * LogQuat<T>(q_i.conjugate() * q_j);
    const Eigen::Quaternion<T> q_m = q_i * ExpQuat<T>(half);
    const Eigen::Matrix<T, 3, 1> da = AxlePoint<T>(p_j, q_j, lever_b) - AxlePoint<T>(p_i, q_i, lever_b);
    return (q_m.conjugate() * da).template tail<2>() / T(dt);
  }
};

struct WheelYawModel {
  static constexpr int kResidualDim = 1;
  template <typename T>
  static T Residual(const Eigen::Quaternion<T>& q_i, const Eigen::Quaternion<T>& q_j, const T& scale,
                    double yaw_change) {
    return scale * LogQuat<T>(q_i.conjugate() * q_j).z() - T(yaw_change);
  }
};

}  // namespace gins
