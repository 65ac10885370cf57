// The kinematic state at t − τ from the state at t: how a GNSS record stamped τ after its measurement
// (gnss.time_offset_s) is compared with a state at its stamp. Second order in τ with the acceleration a_w and
// the body rate ω_b held over τ (their IMU values at t):
//   p(t − τ) = p − v·τ + ½·a_w·τ²,   v(t − τ) = v − a_w·τ,   R(t − τ) = R·Exp(−ω_b·τ)
// At 2 m/s² and τ = 0.25 s the neglected third-order term is below 1 mm for a jerk under 0.4 m/s³.
#pragma once

#include "core/so3.h"

namespace gins {

template <typename T>
struct ShiftedKinematics {
  Eigen::Matrix<T, 3, 1> p_wb, v_w;
  Eigen::Quaternion<T> q_wb;
};

template <typename T>
ShiftedKinematics<T> ShiftBack(const Eigen::Matrix<T, 3, 1>& p_wb, const Eigen::Matrix<T, 3, 1>& v_w,
                               const Eigen::Quaternion<T>& q_wb, const Vec3& a_w, const Vec3& omega_b, const T& tau) {
  ShiftedKinematics<T> s;
  s.p_wb = p_wb - v_w * tau + a_w.cast<T>() * (T(0.5) * tau * tau);
  s.v_w = v_w - a_w.cast<T>() * tau;
  s.q_wb = q_wb * ExpQuat<T>(Eigen::Matrix<T, 3, 1>(-omega_b.cast<T>() * tau));
  return s;
}

}  // namespace gins
