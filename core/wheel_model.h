// Wheel-speed model: the body's forward speed scaled by the odometer scale factor against the speed
// from the encoders; optionally the non-holonomic constraint (no lateral, no vertical body speed).
//   r_speed = s·(R_wbᵀ·v_w).x − v_meas          (m/s; 1)
//   r_nhc   = ((R_wbᵀ·v_w).y, (R_wbᵀ·v_w).z)    (m/s; 2)
#pragma once

#include "core/conventions.h"

namespace gins {

struct WheelSpeedModel {
  static constexpr int kResidualDim = 1;

  template <typename T>
  static T Residual(const Eigen::Quaternion<T>& q_wb, const Eigen::Matrix<T, 3, 1>& v_w, const T& scale,
                    double speed_meas) {
    const Eigen::Matrix<T, 3, 1> v_b = q_wb.conjugate() * v_w;
    return scale * v_b.x() - T(speed_meas);
  }
};

struct NonHolonomicModel {
  static constexpr int kResidualDim = 2;

  template <typename T>
  static Eigen::Matrix<T, 2, 1> Residual(const Eigen::Quaternion<T>& q_wb, const Eigen::Matrix<T, 3, 1>& v_w) {
    const Eigen::Matrix<T, 3, 1> v_b = q_wb.conjugate() * v_w;
    return v_b.template tail<2>();
  }
};

// The wheels' reference point is the rear-axle centre at lever_b in the body frame (wheel.lever_arm_m): the
// point a car's non-holonomic constraint holds at, and whose forward speed the mean of two wheel speeds is.
// Its velocity in b, with ω_b the body rate against w (the gyro reading less its bias; the Earth rate is
// 1e-4 of a turn's and left out here):
//   v_a = R_wbᵀ·v_w + ω_b × lever_b
// With the lever arm:
//   r_speed = s·v_a.x − v_meas,   r_nhc = (v_a.y, v_a.z)
template <typename T>
Eigen::Matrix<T, 3, 1> AxleVelocity(const Eigen::Quaternion<T>& q_wb, const Eigen::Matrix<T, 3, 1>& v_w,
                                    const Vec3& omega_b, const Vec3& lever_b) {
  return q_wb.conjugate() * v_w + omega_b.cross(lever_b).cast<T>();
}

struct AxleSpeedModel {
  static constexpr int kResidualDim = 1;
  template <typename T>
  static T Residual(const Eigen::Quaternion<T>& q_wb, const Eigen::Matrix<T, 3, 1>& v_w, const T& scale,
                    const Vec3& omega_b, const Vec3& lever_b, double speed_meas) {
    return scale * AxleVelocity<T>(q_wb, v_w, omega_b, lever_b).x() - T(speed_meas);
  }
};

struct AxleNhcModel {
  static constexpr int kResidualDim = 2;
  template <typename T>
  static Eigen::Matrix<T, 2, 1> Residual(const Eigen::Quaternion<T>& q_wb, const Eigen::Matrix<T, 3, 1>& v_w,
                                         const Vec3& omega_b, const Vec3& lever_b) {
    return AxleVelocity<T>(q_wb, v_w, omega_b, lever_b).template tail<2>();
  }
};

// Forward speed of one wheel from its pulse count: v = 2π·r·pulses / (n·Δt).
inline double WheelSpeedFromPulses(double pulses, double wheel_radius, double pulses_per_rev, double dt) {
  return 2.0 * kPi * wheel_radius * pulses / (pulses_per_rev * dt);
}

}  // namespace gins
