#include "core/geodesy.h"

#include <GeographicLib/Constants.hpp>
#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/NormalGravity.hpp>
#include <cmath>
#include <vector>

namespace gins {

LocalEnuFrame::LocalEnuFrame(const GeodeticPoint& origin)
    : origin_(origin),
      proj_(std::make_unique<GeographicLib::LocalCartesian>(origin.lat_deg, origin.lon_deg, origin.alt_m)) {}

LocalEnuFrame::~LocalEnuFrame() = default;

LocalEnuFrame::LocalEnuFrame(const LocalEnuFrame& other) : LocalEnuFrame(other.origin_) {}

LocalEnuFrame& LocalEnuFrame::operator=(const LocalEnuFrame& other) {
  if (this != &other) {
    origin_ = other.origin_;
    proj_ = std::make_unique<GeographicLib::LocalCartesian>(origin_.lat_deg, origin_.lon_deg, origin_.alt_m);
  }
  return *this;
}

Vec3 LocalEnuFrame::ToEnu(const GeodeticPoint& p) const {
  Vec3 enu;
  proj_->Forward(p.lat_deg, p.lon_deg, p.alt_m, enu.x(), enu.y(), enu.z());
  return enu;
}

GeodeticPoint LocalEnuFrame::ToGeodetic(const Vec3& p_w) const {
  GeodeticPoint g;
  proj_->Reverse(p_w.x(), p_w.y(), p_w.z(), g.lat_deg, g.lon_deg, g.alt_m);
  return g;
}

Vec3 LocalEnuFrame::OriginEcef() const {
  Vec3 r;
  GeographicLib::Geocentric::WGS84().Forward(origin_.lat_deg, origin_.lon_deg, origin_.alt_m, r.x(), r.y(), r.z());
  return r;
}

Mat3 LocalEnuFrame::R_ecef_w() const {
  // Geocentric's M takes local ENU components into ECEF (row-major).
  std::vector<double> M(9);
  double x, y, z;
  GeographicLib::Geocentric::WGS84().Forward(origin_.lat_deg, origin_.lon_deg, origin_.alt_m, x, y, z, M);
  Mat3 R;
  R << M[0], M[1], M[2], M[3], M[4], M[5], M[6], M[7], M[8];
  return R;
}

Mat3 LocalEnuFrame::RotationFromLocalEnu(const GeodeticPoint& p) const {
  std::vector<double> M(9);
  double x = 0.0, y = 0.0, z = 0.0;
  proj_->Forward(p.lat_deg, p.lon_deg, p.alt_m, x, y, z, M);
  Mat3 R_w_l;
  R_w_l << M[0], M[1], M[2], M[3], M[4], M[5], M[6], M[7], M[8];
  return R_w_l;
}

GeodeticPoint NearGeodetic::operator()(const Vec3& p_w) {
  if (!p_w.allFinite()) return frame_.ToGeodetic(p_w);
  // Near a pole the longitude's derivative blows up: exact there.
  if (has_reference_ && std::abs(reference_.lat_deg) > 89.0) {
    has_reference_ = false;
    return frame_.ToGeodetic(p_w);
  }
  if (!has_reference_ || (p_w - reference_w_).squaredNorm() > kReach * kReach) {
    reference_w_ = p_w;
    reference_ = frame_.ToGeodetic(p_w);
    has_reference_ = true;
    // d(lat, lon, h) / d(east, north, up) at the reference: the meridian and prime-vertical radii of
    // curvature (WGS84), after turning w's axes into the local ENU ones there.
    const double a = GeographicLib::Constants::WGS84_a(), f = GeographicLib::Constants::WGS84_f();
    const double e2 = f * (2.0 - f);
    const double phi = reference_.lat_deg * M_PI / 180.0;
    const double w = 1.0 - e2 * std::sin(phi) * std::sin(phi);
    const double N = a / std::sqrt(w), M = a * (1.0 - e2) / (w * std::sqrt(w));
    Mat3 d_local;
    d_local << 0.0, 180.0 / M_PI / (M + reference_.alt_m), 0.0,  // latitude from north
        180.0 / M_PI / ((N + reference_.alt_m) * std::cos(phi)), 0.0, 0.0,  // longitude from east
        0.0, 0.0, 1.0;                                                      // height from up
    d_geodetic_d_w_ = d_local * frame_.RotationFromLocalEnu(reference_).transpose();
  }
  const Vec3 d = d_geodetic_d_w_ * (p_w - reference_w_);
  GeodeticPoint g{reference_.lat_deg + d.x(), reference_.lon_deg + d.y(), reference_.alt_m + d.z()};
  if (g.lon_deg > 180.0) g.lon_deg -= 360.0;
  if (g.lon_deg < -180.0) g.lon_deg += 360.0;
  return g;
}

double LocalYawToWorld(const LocalEnuFrame& frame, const GeodeticPoint& p, double yaw_local) {
  const Vec3 d_w = frame.RotationFromLocalEnu(p) * Vec3(std::cos(yaw_local), std::sin(yaw_local), 0.0);
  return std::atan2(d_w.y(), d_w.x());
}

double NormalGravity(double lat_deg, double alt_m) {
  // Gravity (gravitation + centrifugal) of the WGS84 ellipsoid: northward and upward components.
  double gamma_y = 0.0, gamma_z = 0.0;
  GeographicLib::NormalGravity::WGS84().Gravity(lat_deg, alt_m, gamma_y, gamma_z);
  return std::hypot(gamma_y, gamma_z);
}

bool IsPlausibleGeodetic(double lat_deg, double lon_deg, double alt_m) {
  return std::isfinite(lat_deg) && std::isfinite(lon_deg) && std::isfinite(alt_m) && std::abs(lat_deg) <= 90.0 &&
         std::abs(lon_deg) <= 180.0 && alt_m > -1000.0 && alt_m < 100000.0;
}

}  // namespace gins
