// Standstill detection, for the zero-velocity and zero-rotation updates and for the static initialisation
// (StandstillOptions).
//
// Standing = the IMU is quiet over the last window (per-axis standard deviations of gyro and accelerometer
// below their thresholds, mean rate below 1 deg/s, |mean specific force| within 0.3 m/s² of |g|: a steady
// turn is not quiet; the means over the newest and the oldest fifth of the window within half those
// thresholds: a gentle start is not quiet either), AND a witness agrees that the vehicle does not move.
// A quiet IMU alone is not enough: a vehicle cruising at constant speed on a smooth road looks as quiet as a
// parked one. The witnesses, best first:
//   wheels        when the log has encoders (a wheel record within the window or two counting intervals):
//                 every wheel record in the window counted zero pulses;
//   GNSS velocity (GVEL records) over the stretch the IMU has been quiet: their mean is zero within its
//                 uncertainty (χ², 99.9 %) and below standstill.max_speed_m_s by 3 σ;
//   GNSS position the fixes over that stretch: the speed of a straight line fitted through them, likewise.
// GNSS witnesses need time to agree (metre-level single-point fixes at 5 Hz: about 4 s). When the log has
// neither encoders nor GNSS over the stretch (an outage), nothing can witness: the detection is
// "unwitnessed" and the estimators check it against their own speed (standstill.max_speed_m_s).
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
  double max_speed = 0.5;                 // standstill.max_speed_m_s: a standstill is slower than this
};

class StandstillDetector {
 public:
  enum class Witness { kNone, kWheels, kGnssVelocity, kGnssPosition };
  enum class State {
    kMoving,            // the IMU is not quiet, or a witness says the vehicle moves
    kUndecided,         // quiet, but the GNSS cannot tell yet
    kStanding,          // quiet and a witness agrees
    kQuietUnwitnessed,  // quiet, and no encoders nor GNSS to ask
  };

  StandstillDetector(const StandstillOptions& options, double g_norm, double wheel_interval);

  // Samples and measurements in time order (IMU in body axes, GNSS in w).
  void AddImu(const ImuSample& imu);
  void AddWheel(const WheelMeasurement& wheel);
  void AddGnss(const GnssMeasurement& fix);
  void AddGvel(const GvelMeasurement& vel);

  // At the newest IMU sample.
  State Decide() const;
  // Standing, or quiet with nothing to witness (the estimators then check their own speed).
  bool Standing() const;
  bool ImuQuiet() const { return quiet_since_ >= 0.0; }
  // Start of the current quiet stretch (< 0: not quiet).
  double quiet_since() const { return quiet_since_; }
  // What decided the last kStanding or kMoving (kNone: nothing could).
  Witness witness() const;
  bool WheelsPresent() const;

 private:
  bool WindowQuiet() const;
  // The GNSS's verdict over the quiet stretch: kStanding, kMoving, kUndecided, or kQuietUnwitnessed when
  // there is nothing to judge by; *witness says which record type decided.
  State GnssVerdict(Witness* witness) const;

  StandstillOptions options_;
  double g_norm_;
  double wheel_interval_;
  std::deque<ImuSample> imu_;
  std::deque<WheelMeasurement> wheels_;
  std::deque<GnssMeasurement> fixes_;
  std::deque<GvelMeasurement> gvels_;
  double t_ = 0.0;             // newest IMU time
  double quiet_since_ = -1.0;  // start of the quiet stretch
};

const char* WitnessName(StandstillDetector::Witness w);

}  // namespace gins
