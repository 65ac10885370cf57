#include "core/earth.h"

#include <GeographicLib/NormalGravity.hpp>

#include <cmath>

namespace gins {

Vec3 NormalGravityWorld(const LocalEnuFrame& frame, const Vec3& p_w) {
  const GeodeticPoint geo = frame.ToGeodetic(p_w);
  double gamma_north = 0.0, gamma_up = 0.0;  // in the local ENU frame at geo
  GeographicLib::NormalGravity::WGS84().Gravity(geo.lat_deg, geo.alt_m, gamma_north, gamma_up);
  return frame.RotationFromLocalEnu(geo) * Vec3(0.0, gamma_north, gamma_up);
}

EarthModel::EarthModel(double g_norm) : g_norm_(g_norm) { g_centre_ = GravityWorld(g_norm); }

EarthModel EarthModel::FromOptions(const LocalEnuFrame& frame, const GravityOptions& options) {
  if (options.earth_rotation && options.use_normal_gravity) return Rotating(frame);
  EarthModel e(options.use_normal_gravity ? NormalGravity(frame.origin().lat_deg, frame.origin().alt_m)
                                          : options.magnitude);
  if (options.earth_rotation) {
    e.rotating_ = true;
    const double lat = frame.origin().lat_deg * kDegToRad;
    e.rate_w_ = kEarthRate * Vec3(0.0, std::cos(lat), std::sin(lat));
  }
  return e;
}

EarthModel EarthModel::Rotating(const LocalEnuFrame& frame) {
  EarthModel e;
  e.rotating_ = true;
  e.by_position_ = true;
  e.frame_.emplace(frame);
  const double lat = frame.origin().lat_deg * kDegToRad;
  e.rate_w_ = kEarthRate * Vec3(0.0, std::cos(lat), std::sin(lat));
  e.Refresh(Vec3::Zero());
  e.g_norm_ = e.g_centre_.norm();
  return e;
}

void EarthModel::Refresh(const Vec3& centre_w) const {
  centre_w_ = centre_w;
  g_centre_ = NormalGravityWorld(*frame_, centre_w);
  // Central differences over ±10 m: the gradient (~3e-6 /s²) to a few parts in 1e6, far below what matters.
  constexpr double kStep = 10.0;
  for (int i = 0; i < 3; ++i) {
    const Vec3 d = kStep * Vec3::Unit(i);
    gradient_.col(i) =
        (NormalGravityWorld(*frame_, centre_w + d) - NormalGravityWorld(*frame_, centre_w - d)) / (2.0 * kStep);
  }
}

Vec3 EarthModel::Gravity(const Vec3& p_w) const {
  if (!by_position_) return g_centre_;
  const Vec3 d = p_w - centre_w_;
  if (!(d.squaredNorm() <= kRefreshDistance * kRefreshDistance)) {
    if (!p_w.allFinite()) return g_centre_;  // a diverged state must not poison the cache
    Refresh(p_w);
    return g_centre_;
  }
  return g_centre_ + gradient_ * d;
}

}  // namespace gins
