// NavState: the navigation state as a value type, with the right-perturbation ⊞/⊟ of core/conventions.h.
// Tangent order (15): δp, δv, δθ, δbg, δba — the first 15 of the ESKF error state.
#pragma once

#include "core/conventions.h"

namespace gins {

namespace nav {
constexpr int kP = 0;
constexpr int kV = 3;
constexpr int kTheta = 6;
constexpr int kBg = 9;
constexpr int kBa = 12;
constexpr int kDim = 15;
}  // namespace nav

struct NavState {
  double t = 0.0;
  Vec3 p_wb = Vec3::Zero();
  Vec3 v_w = Vec3::Zero();
  Quat q_wb = Quat::Identity();
  Vec3 bg = Vec3::Zero();  // gyro bias, rad/s
  Vec3 ba = Vec3::Zero();  // accelerometer bias, m/s²

  Mat3 R_wb() const { return q_wb.toRotationMatrix(); }

  // x ⊞ δ: p + δp, v + δv, q·Exp(δθ), bg + δbg, ba + δba.
  NavState Boxplus(const Vec15& delta) const;
  // this ⊟ x0: the δ with x0 ⊞ δ = this (rotation part Log(q0⁻¹·q)).
  Vec15 Boxminus(const NavState& x0) const;
  bool AllFinite() const;
};

}  // namespace gins
