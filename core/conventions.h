// The conventions every part of gins shares. Fixed here, once (for users: docs/formats.md §2).
//
// Frames
//   w  world: local East-North-Up tangent plane at a geodetic origin (GeographicLib LocalCartesian).
//   b  body = IMU frame, x forward, y left, z up (FLU).
//   G  GNSS antenna frame: R_bG = Rz(mount_yaw), origin at lever_b in b.
// Names say the frame: R_wb takes body vectors into w; p_wb is the body origin in w; v_w is the body
// velocity in w; lever_b is a vector expressed in b.
//
// Perturbation: right, R ⊞ δθ = R·Exp(δθ) with full-angle δθ; p, v, biases additive. The ESKF error state
// and the smoother's tangent spaces use this same ⊞ (core/nav_state.h), so a covariance means the same
// thing in both estimators. Quaternions are Hamilton, Eigen storage order (x, y, z, w).
//
// IMU model: ω̃ = ω + bg + ηg,  ã = R_wbᵀ(a_w − g_w) + ba + ηa;  g_w = (0, 0, −|g|).
// Units: SI inside (m, s, rad). Time: seconds as double.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace gins {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Vec15 = Eigen::Matrix<double, 15, 1>;
using VecX = Eigen::VectorXd;
using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat15 = Eigen::Matrix<double, 15, 15>;
using MatX = Eigen::MatrixXd;
using Quat = Eigen::Quaterniond;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
constexpr double kRadToDeg = 180.0 / kPi;
// Standard gravity, used only when the config asks for a fixed |g| without giving one.
constexpr double kStandardGravity = 9.80665;

// Wraps an angle to (−π, π].
inline double WrapAngle(double a) {
  a = std::fmod(a + kPi, 2.0 * kPi);
  if (a <= 0.0) a += 2.0 * kPi;
  return a - kPi;
}

// Heading as logged (deg, clockwise from true north) <-> yaw in ENU (rad, counter-clockwise from east).
inline double CompassDegToEnuYaw(double heading_deg) { return WrapAngle((90.0 - heading_deg) * kDegToRad); }
inline double EnuYawToCompassDeg(double yaw) {
  double h = 90.0 - yaw * kRadToDeg;
  h = std::fmod(h, 360.0);
  return h < 0.0 ? h + 360.0 : h;
}

// The yaw's 1-σ when nothing is known of it: that of a uniform angle on the circle, π/√3 (104°). An estimate
// with it (a state at rest before the initialisation, core/initializer.h) has no yaw: evaluations leave its
// attitude out (core/eval/trajectory_metrics.h). Any σ of at least kUnknownYawSigmaBound reads as unknown.
inline constexpr double kUnknownYawSigma = 1.8137993642342178;
inline constexpr double kUnknownYawSigmaBound = 0.99 * kUnknownYawSigma;

inline Vec3 GravityWorld(double g_norm) { return Vec3(0.0, 0.0, -g_norm); }

}  // namespace gins
