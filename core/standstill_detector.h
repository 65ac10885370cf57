// Standstill detection for the zero-velocity and zero-rotation updates (StandstillOptions).
//
// Standing = the IMU is quiet over the last standstill.window_s (per-axis standard deviations of gyro and
// accelerometer below their thresholds, mean rate below 1 deg/s, |mean specific force| within 0.3 m/s² of
// |g|: a steady turn is not quiet; the means over the newest and the oldest fifth of the window within half
// those thresholds: a gentle start is not quiet either), AND, when the log has wheel encoders (a wheel record
// within the window, or within two counting intervals, whichever is longer), every wheel record in the
// window counted zero pulses. Without encoders the quiet IMU alone decides; the estimators then also check
// their own speed estimate (standstill.max_speed_m_s), since a vehicle cruising on a smooth road can look
// as quiet as a parked one.
#pragma once

#include <deque>

#include "core/conventions.h"
#include "core/measurements.h"

namespace gins {

// standstill.*: zero-velocity and zero-rotation updates while the vehicle stands (core/standstill_detector.h).
struct StandstillOptions {
  bool enabled = true;                    // standstill.enabled
  double window = 1.0;                    // standstill.window_s: IMU samples judged together
  double max_gyro_std = 0.5 * kDegToRad;  // standstill.max_gyro_std_deg_s: "IMU quiet" thresholds
  double max_acc_std = 0.1;               // standstill.max_acc_std_m_s2
  double velocity_sigma = 0.01;           // standstill.velocity_sigma_m_s: 1-σ of the zero velocity
  double max_speed = 0.5;                 // standstill.max_speed_m_s: ignore a detection above this speed
};

class StandstillDetector {
 public:
  StandstillDetector(const StandstillOptions& options, double g_norm, double wheel_interval);

  // Samples in time order (IMU in body axes).
  void AddImu(const ImuSample& imu);
  void AddWheel(const WheelMeasurement& wheel);

  // At the newest IMU sample: is the vehicle standing?
  bool Standing() const;
  bool ImuQuiet() const;
  // Whether the wheels took part in the last decision (encoders present).
  bool WheelsPresent() const;

 private:
  StandstillOptions options_;
  double g_norm_;
  double wheel_interval_;
  std::deque<ImuSample> imu_;
  std::deque<WheelMeasurement> wheels_;
  double t_ = 0.0;  // newest IMU time
};

}  // namespace gins
