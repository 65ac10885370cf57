#include "core/geodesy.h"

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

Mat3 LocalEnuFrame::RotationFromLocalEnu(const GeodeticPoint& p) const {
  std::vector<double> M(9);
  double x = 0.0, y = 0.0, z = 0.0;
  proj_->Forward(p.lat_deg, p.lon_deg, p.alt_m, x, y, z, M);
  Mat3 R_w_l;
  R_w_l << M[0], M[1], M[2], M[3], M[4], M[5], M[6], M[7], M[8];
  return R_w_l;
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
