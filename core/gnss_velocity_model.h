// GNSS (Doppler) velocity model: the antenna's velocity in w against the measured one (GVEL records,
// docs/formats.md §3.5). The antenna sits at lever_b; ω_b is the body rate (gyro less bias):
//   r = v_w + R_wb·(ω_b × lever_b) − z_w        (m/s, world ENU; 3)
#pragma once

#include "core/conventions.h"

namespace gins {

struct GnssVelocityModel {
  static constexpr int kResidualDim = 3;

  template <typename T>
  static Eigen::Matrix<T, 3, 1> Residual(const Eigen::Quaternion<T>& q_wb, const Eigen::Matrix<T, 3, 1>& v_w,
                                         const Vec3& omega_b, const Vec3& lever_b, const Vec3& z_w) {
    return v_w + q_wb * omega_b.cross(lever_b).cast<T>() - z_w.cast<T>();
  }
};

}  // namespace gins
