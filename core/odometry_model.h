// The vehicle's motion between two keyframes i and j, as the wheels and the non-holonomic constraint see it
// (the smoother's odometer, chord and wheel-yaw factors; the ESKF uses the instantaneous forms of
// core/wheel_model.h at every record). a = p_wb + R_wb·lever_b is the rear-axle centre (core/wheel_model.h).
//
// Odometer: the encoders' displacement over the interval, D_i = Σ_k ΔR_ik·e_x·d_k in the body frame at i (d_k
// the distance of record k, ΔR_ik the preintegrated rotation at its middle), against the axle's
// displacement in that frame, along D's direction u (e_x when the vehicle stood):
//   r_odo = s·uᵀ·R_iᵀ·(a_j − a_i) − |D_i|                       (m; 1)
// Chord (the non-holonomic constraint between keyframes): the axle moves along its body x axis at every
// instant, so its displacement in the body frame at i points along the path P_i = ∫ ΔR_i(t)·e_x·v_x(t) dt (the
// IMU's relative attitude and the axle's forward speed over the interval; exact in any turn and at any
// speed profile, where the attitude halfway between i and j is exact only on an arc at constant speed). The
// residual is what lies across u = P_i/|P_i| (e_x at a standstill), in the basis N_i = (n_lat, n_vert) of
// ChordModel::Basis:
//   r_chord = N_i·R_iᵀ·(a_j − a_i) / Δt            (m/s, a mean lateral and vertical speed; 2)
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
  // The rows n_latᵀ, n_vertᵀ across the path direction P_i: n_lat = e_z × u (sideways, as the body y axis for
  // u = e_x), n_vert = u × n_lat. A path shorter than 1 mm (a standstill) is taken along e_x.
  static Eigen::Matrix<double, 2, 3> Basis(const Vec3& path_i) {
    const double length = path_i.norm();
    const Vec3 u = length > 1e-3 ? Vec3(path_i / length) : Vec3::UnitX();
    // A path (nearly) along the body z axis, never a car's: the sideways axis from e_x instead.
    const Vec3 side = std::abs(u.z()) < 0.9 ? Vec3(Vec3::UnitZ().cross(u)) : Vec3(u.cross(Vec3::UnitX()));
    const Vec3 n_lat = side.normalized();
    Eigen::Matrix<double, 2, 3> n;
    n.row(0) = n_lat.transpose();
    n.row(1) = u.cross(n_lat).transpose();
    return n;
  }
  // across_i: Basis(P_i).
  template <typename T>
  static Eigen::Matrix<T, 2, 1> Residual(const Eigen::Matrix<T, 3, 1>& p_i, const Eigen::Quaternion<T>& q_i,
                                         const Eigen::Matrix<T, 3, 1>& p_j, const Eigen::Quaternion<T>& q_j,
                                         const Vec3& lever_b, const Eigen::Matrix<double, 2, 3>& across_i,
                                         double dt) {
    const Eigen::Matrix<T, 3, 1> da = AxlePoint<T>(p_j, q_j, lever_b) - AxlePoint<T>(p_i, q_i, lever_b);
    return across_i.cast<T>() * (q_i.conjugate() * da) / T(dt);
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
