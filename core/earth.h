// The Earth as the estimators see it from the working frame w (core/conventions.h): w is the East-North-Up tangent
// frame at a geodetic origin, fixed to the Earth, so it turns with the Earth against inertial space.
//
// With the rotating model (gravity.earth_rotation: true, the default):
// - the gyro measures ω_ib = ω_wb + R_wbᵀ·ω_ie^w, with ω_ie^w = Ω·(0, cos φ0, sin φ0) (Ω = WGS84 rate,
//   φ0 the origin's latitude): Earth rate is constant in w;
// - the velocity in w obeys v̇ = R_wb·f + g_w(p) − 2·ω_ie^w × v (Coriolis);
// - g_w(p) is WGS84 normal gravity (gravitation plus the centrifugal term of the Earth's rotation) at the
//   vehicle's position, expressed in w: its direction follows the local vertical, which turns by
//   distance / Earth radius as the vehicle moves away from the origin. In an Earth-fixed tangent frame this
//   is what the transport rate of a local-level navigation frame becomes: w does not move with the vehicle,
//   the plumb line does.
// With the flat model (false): no Earth rate, no Coriolis, and g_w = (0, 0, −|g|) everywhere, |g| normal
// gravity at the origin or gravity.magnitude_m_s2 (the reference book's model, which only consumer-grade IMUs
// can afford: Earth rate is 15 deg/h).
#pragma once

#include <optional>

#include "core/conventions.h"
#include "core/geodesy.h"
#include "core/sensors.h"

namespace gins {

// Earth's rotation rate (WGS84), rad/s.
constexpr double kEarthRate = 7.2921151467e-5;

class EarthModel {
 public:
  // The flat, non-rotating model with constant gravity g_w = (0, 0, −g_norm).
  explicit EarthModel(double g_norm = kStandardGravity);
  // The rotating model about the frame's origin, with WGS84 normal gravity.
  static EarthModel Rotating(const LocalEnuFrame& frame);
  // What the options ask for at this origin: gravity.earth_rotation picks rotating or flat;
  // gravity.model picks normal gravity (by position when rotating, at the origin when flat) or the fixed
  // magnitude (constant, straight down).
  static EarthModel FromOptions(const LocalEnuFrame& frame, const GravityOptions& options);

  bool rotating() const { return rotating_; }
  // ω_ie in w (rad/s); zero for the flat model.
  const Vec3& rate_w() const { return rate_w_; }
  // Gravity in w at a position p_w (m/s²). Linear about a centre that follows the vehicle (refreshed beyond
  // kRefreshDistance, where the linearisation error is ~1e-7 m/s², 0.01 µg), so a call costs a 3×3 product.
  Vec3 Gravity(const Vec3& p_w) const;
  // |g| at the origin (for the summary and the flat model).
  double g_norm() const { return g_norm_; }
  // The same Earth for a mechanisation run backwards in time (t' = −t, v' = −v, ω' = −ω): the rotation's
  // terms (Coriolis, the frame's turn) change sign, gravity with its centrifugal part does not.
  EarthModel TimeReversed() const {
    EarthModel e = *this;
    e.rate_w_ = -rate_w_;
    return e;
  }

  // Distance from the linearisation centre beyond which Gravity recomputes it (m).
  static constexpr double kRefreshDistance = 500.0;

 private:
  void Refresh(const Vec3& centre_w) const;

  bool rotating_ = false;
  bool by_position_ = false;  // gravity from the frame's normal gravity at each position
  double g_norm_ = kStandardGravity;
  Vec3 rate_w_ = Vec3::Zero();
  std::optional<LocalEnuFrame> frame_;  // the rotating model's
  // Gravity linearised about centre_w_: g(p) = g_centre_ + gradient_·(p − centre_w_). Mutable: a cache the
  // single-threaded estimators refresh as they move (each estimator holds its own copy).
  mutable Vec3 centre_w_ = Vec3::Zero();
  mutable Vec3 g_centre_ = Vec3::Zero();
  mutable Mat3 gradient_ = Mat3::Zero();
};

// Exact WGS84 normal gravity (with the centrifugal term) at p_w, in w.
Vec3 NormalGravityWorld(const LocalEnuFrame& frame, const Vec3& p_w);

}  // namespace gins
