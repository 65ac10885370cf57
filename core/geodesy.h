// Geodetic <-> local ENU tangent frame through GeographicLib (WGS84), and normal gravity.
#pragma once

#include <memory>

#include "core/conventions.h"

namespace GeographicLib {
class LocalCartesian;
}

namespace gins {

struct GeodeticPoint {
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  double alt_m = 0.0;
};

// The world frame w: ENU at a geodetic origin.
class LocalEnuFrame {
 public:
  explicit LocalEnuFrame(const GeodeticPoint& origin);
  ~LocalEnuFrame();
  LocalEnuFrame(const LocalEnuFrame& other);
  LocalEnuFrame& operator=(const LocalEnuFrame& other);

  const GeodeticPoint& origin() const { return origin_; }
  Vec3 ToEnu(const GeodeticPoint& p) const;
  GeodeticPoint ToGeodetic(const Vec3& p_w) const;
  // R_w_l: takes vectors in the local ENU frame at p (e.g. a truth file's attitude or velocity) into w.
  // Differs from identity by about distance / Earth radius (0.01° at 1 km).
  Mat3 RotationFromLocalEnu(const GeodeticPoint& p) const;
  // w is the ENU tangent frame at the origin, so r_ecef = OriginEcef() + R_ecef_w()·p_w exactly (WGS 84).
  Vec3 OriginEcef() const;
  Mat3 R_ecef_w() const;

 private:
  GeodeticPoint origin_;
  std::unique_ptr<GeographicLib::LocalCartesian> proj_;
};

// ToGeodetic for a track of nearby points (an IMU-rate output): exact at a reference point, to first order in
// the offset from it within kReach, the reference renewed beyond; the neglected second order is below
// |offset|²/R, 4 µm at 5 m, under the 0.1 mm of the outputs' 9 decimals of a degree. A tenth of the cost.
class NearGeodetic {
 public:
  static constexpr double kReach = 5.0;  // m
  explicit NearGeodetic(const LocalEnuFrame& frame) : frame_(frame) {}
  GeodeticPoint operator()(const Vec3& p_w);
  const LocalEnuFrame& frame() const { return frame_; }

 private:
  LocalEnuFrame frame_;
  bool has_reference_ = false;
  Vec3 reference_w_ = Vec3::Zero();
  GeodeticPoint reference_;
  Mat3 d_geodetic_d_w_ = Mat3::Zero();  // rows: deg of latitude, deg of longitude, m of height per m in w
};

// A yaw measured in the local ENU frame at p (e.g. a heading against true north there), as a yaw in w: the
// two differ by the meridian convergence, about Δlon·sin(lat) (0.01° at 1 km east at 30°).
double LocalYawToWorld(const LocalEnuFrame& frame, const GeodeticPoint& p, double yaw_local);

// Magnitude of WGS84 normal gravity at a latitude and height (m/s²).
double NormalGravity(double lat_deg, double alt_m);

// True when lat/lon/alt are finite and in range (|lat| ≤ 90, |lon| ≤ 180, −1000 m < alt < 100 km).
bool IsPlausibleGeodetic(double lat_deg, double lon_deg, double alt_m);

}  // namespace gins
