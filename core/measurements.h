// Measurement value types: raw records as read from a log, and the processed measurements the
// estimators consume (in the world frame, SI units).
#pragma once

#include <cstdint>

#include "core/conventions.h"

namespace gins {

// IMU sample: angular rate (rad/s) and specific force (m/s²) in body axes (FLU, after axis mapping).
struct ImuSample {
  double t = 0.0;
  Vec3 gyro = Vec3::Zero();
  Vec3 acc = Vec3::Zero();
};

// Wheel encoder pulses counted over (t − Δt, t].
struct WheelRecord {
  double t = 0.0;
  double left_pulses = 0.0;
  double right_pulses = 0.0;
};

// GNSS fix as logged: geodetic position of the antenna and optional dual-antenna heading.
struct GnssRecord {
  double t = 0.0;
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  double alt_m = 0.0;          // ellipsoidal height
  double heading_deg = 0.0;    // clockwise from true north, of the antenna baseline
  bool heading_valid = false;
  bool has_sigma = false;
  Vec3 sigma_enu = Vec3::Zero();  // 1-σ position error (east, north, up), m
};

// GNSS (Doppler) velocity as logged (GVEL records): the antenna's velocity in the local East-North-Up frame
// at the fix, with an optional 1-σ per axis.
struct GnssVelocityRecord {
  double t = 0.0;
  Vec3 v_enu = Vec3::Zero();     // m/s
  bool has_sigma = false;
  Vec3 sigma_enu = Vec3::Zero();  // m/s
};

// A GNSS velocity in the world frame, ready for an estimator.
struct GnssVelocityMeasurement {
  double t = 0.0;
  Vec3 v_w = Vec3::Zero();        // antenna velocity in w, m/s
  Vec3 sigma_w = Vec3::Ones();    // 1-σ per ENU axis, m/s
};

// A GNSS fix in the world frame, ready for an estimator.
struct GnssMeasurement {
  double t = 0.0;
  Vec3 p_w = Vec3::Zero();        // antenna position in w
  Vec3 sigma_w = Vec3::Ones();    // 1-σ per ENU axis, m
  bool heading_valid = false;
  double yaw_G = 0.0;             // yaw of the antenna frame G in w (ENU, rad, CCW from east)
  double sigma_yaw = 0.0;         // rad
};

// Vehicle forward speed from the wheel encoders.
struct WheelMeasurement {
  double t = 0.0;
  double speed = 0.0;   // m/s, mean of both wheels
  double sigma = 0.0;   // m/s
  double interval = 0.0;  // s: the speed is the mean over (t − interval, t]
  bool standstill = false;  // both wheels reported zero pulses
  // The turn rate from the two wheels' speed difference over the track (rad/s, mean over the interval, read
  // with the odometer scale like the speeds), when the track is known.
  bool has_yaw_rate = false;
  double yaw_rate = 0.0;
  double yaw_rate_sigma = 0.0;  // rad/s
  double distance = 0.0;        // m: speed·interval, the axle centre's travel over the interval
};

// The vehicle stands still (core/standstill_detector.h), continuously from `since` to t.
struct StandstillMeasurement {
  double t = 0.0;
  double since = 0.0;
  // False when nothing witnesses the stop (no wheels, no GNSS: an outage): only the quiet IMU and the
  // estimate's own speed say so. Then acc_mean_b, the mean specific force over the detector's window
  // (window_s), lets the estimator check it is not braking smoothly (an IMU as quiet as at rest).
  bool witnessed = true;
  Vec3 acc_mean_b = Vec3::Zero();
  double window_s = 0.0;
};

}  // namespace gins
