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

#include <cmath>
#include <deque>
#include <optional>

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
  void AddGnssVelocity(const GnssVelocityMeasurement& vel);

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
  // The mean specific force over the window (body axes; zero without samples).
  Vec3 WindowMeanAcc() const;

 private:
  bool WindowQuiet() const;
  // Running sums over the window, so that judging it costs O(1) per sample, not O(window): each sample's
  // cumulative sums of gyro and accelerometer deviations from a reference sample (so any stretch's sum is a
  // difference of two), and the window's sums of squared deviations. Rebased on the window's oldest sample
  // once per window length, which bounds the rounding.
  struct CumulativeSums {
    Vec3 g = Vec3::Zero(), a = Vec3::Zero();
  };
  void Rebase();
  CumulativeSums Deviations(const ImuSample& s) const;
  void AppendSums(const ImuSample& s);  // the newest sample of imu_ into cum_ and the squared sums
  // The GNSS's verdict over the quiet stretch: kStanding, kMoving, kUndecided, or kQuietUnwitnessed when
  // there is nothing to judge by; *witness says which record type decided.
  State GnssVerdict(Witness* witness) const;

  StandstillOptions options_;
  double g_norm_;
  double wheel_interval_;
  std::deque<ImuSample> imu_;
  std::deque<CumulativeSums> cum_;  // one per sample of imu_, from the last rebase
  CumulativeSums cum_before_;        // of the samples removed since the last rebase
  Vec3 ref_g_ = Vec3::Zero(), ref_a_ = Vec3::Zero();
  Vec3 sq_g_ = Vec3::Zero(), sq_a_ = Vec3::Zero();  // the window's sums of squared deviations
  size_t removed_ = 0;                              // samples removed since the last rebase
  std::deque<WheelMeasurement> wheels_;
  std::deque<GnssMeasurement> fixes_;
  std::deque<GnssVelocityMeasurement> gnss_velocities_;
  double t_ = 0.0;             // newest IMU time
  double quiet_since_ = -1.0;  // start of the quiet stretch
};

const char* WitnessName(StandstillDetector::Witness w);

// A horizontal velocity the GNSS shows, with its per-axis 1-σ.
struct GnssSpeed {
  Vec2 v = Vec2::Zero();
  double sigma = 0.0;
};

// The mean of the GNSS velocities from t_from on (nullopt: none).
template <typename Gvels>
std::optional<GnssSpeed> MeanGnssVelocity(const Gvels& gnss_velocities, double t_from) {
  Vec2 sum = Vec2::Zero();
  double var = 0.0;
  int n = 0;
  for (const GnssVelocityMeasurement& g : gnss_velocities) {
    if (g.t < t_from) continue;
    sum += g.v_w.template head<2>();
    var += g.sigma_w.template head<2>().squaredNorm() / 2.0;
    ++n;
  }
  if (n == 0) return std::nullopt;
  return GnssSpeed{sum / n, std::sqrt(var) / n};
}

// The velocity of a straight line through the fixes from t_from on, p = a + v·(t − t̄), least squares
// (nullopt: fewer than two epochs).
template <typename Fixes>
std::optional<GnssSpeed> LineThroughFixes(const Fixes& fixes, double t_from) {
  double t_mean = 0.0, var_p = 0.0;
  Vec2 p_mean = Vec2::Zero();
  int n = 0;
  for (const GnssMeasurement& f : fixes) {
    if (f.t < t_from) continue;
    t_mean += f.t;
    p_mean += f.p_w.template head<2>();
    var_p += f.sigma_w.template head<2>().squaredNorm() / 2.0;
    ++n;
  }
  if (n < 2) return std::nullopt;
  t_mean /= n;
  p_mean /= n;
  var_p /= n;
  double stt = 0.0;
  Vec2 stp = Vec2::Zero();
  for (const GnssMeasurement& f : fixes) {
    if (f.t < t_from) continue;
    stt += (f.t - t_mean) * (f.t - t_mean);
    stp += (f.t - t_mean) * (f.p_w.template head<2>() - p_mean);
  }
  if (stt <= 0.0) return std::nullopt;
  return GnssSpeed{stp / stt, std::sqrt(var_p / stt)};
}

// Whether the GNSS rules out a zero horizontal speed (χ², 2 dof, at `probability`).
bool GnssShowsMotion(const GnssSpeed& s, double probability);

}  // namespace gins
