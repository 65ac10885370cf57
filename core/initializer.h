// Initialisation from any start: the initial navigation state and its covariance, from the first seconds of
// a log, without being handed anything but the sensors' description.
//
// Paths, chosen by what the data shows (docs/estimators.md, "Initialisation"):
//   standstill  the IMU is quiet for init.static_duration_s and a witness agrees that the vehicle stands
//               (wheels at zero; without encoders the GNSS velocity or the fixes: a quiet IMU alone may be
//               a cruise, core/standstill_detector.h). Its mean IMU readings give roll, pitch, the gyro bias
//               net of the Earth rate and the accelerometer bias along gravity, its spread the noise
//               levels. Yaw is not observable at rest: the first valid dual-antenna heading completes the
//               initialisation there; without one it waits for the motion.
//   moving      everything else (a log that starts while driving; the motion after a standstill): the joint
//               fit of a window of GNSS and preintegrated IMU (core/alignment.h), with the standstill's
//               readings when the window starts at one.
// Acceptance (checked at most once a second of log, at a GNSS epoch): the fit's yaw σ is at most
// init.max_attitude_sigma_deg; its roll/pitch σ at most that or what the accelerometer bias prior allows
// (init_acc_bias_sigma / g), whichever is larger; and no other yaw explains the window nearly as well
// (χ² difference above the 99.99 % quantile of χ²(1), scaled by the residuals' inflation). Once the window
// is full (it slides from then on and the fit gets no better), a yaw σ up to 30° is accepted if no other
// yaw is within that χ² quantile unscaled: a slow rover on metre-level fixes may never do better. The window
// starts at the last standstill or slides: at most as long as the IMU's stated white noise allows for the
// fixes' σ (ImuWindowForSigma, 5-60 s), and it restarts after an IMU gap.
// The estimators start at the completing GNSS epoch with the fit's state and covariance there, having used
// every earlier measurement through the initialiser (no measurement is used twice).
// Before that, while the vehicle stands and a fix has come, what is known is written (RestStates): the
// position of the standstill's fixes, a zero velocity, roll and pitch from gravity, and the yaw from the
// Earth's rotation when the gyro's stated bias σ resolves it (gyrocompassing: tactical and navigation-grade
// IMUs), else a yaw of 0 with the σ of a uniformly unknown angle (π/√3); the two-sided outputs later give
// those epochs the yaw found from the motion (solver/pre_init_output.h). Everything since the first fix goes
// with the result (InitResult::pre_init_*) for the backward runs there.
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "core/alignment.h"
#include "core/earth.h"
#include "core/measurements.h"
#include "core/nav_state.h"
#include "core/sensors.h"
#include "core/standstill_detector.h"

namespace gins {

// init.*
struct InitOptions {
  double static_duration = 2.0;  // init.static_duration_s: standstill needed for the static path
  double max_wait = 300.0;       // init.max_wait_s: give up if not initialised by then
  bool wait_for_heading = false;  // init.wait_for_heading: take the yaw only from a dual-antenna heading
  // init.max_attitude_sigma_deg: accept the fit when its yaw 1-σ is below this (roll and pitch: below this
  // or what the accelerometer bias prior allows).
  double max_attitude_sigma = 1.0 * kDegToRad;
};

struct InitResult {
  NavState x0;                    // at x0.t, the GNSS epoch that completed the initialisation
  Mat15 P0 = Mat15::Identity();   // covariance in the NavState tangent (δp, δv, δθ, δbg, δba)
  double g_norm = kStandardGravity;
  EarthModel earth;               // the Earth the estimators start in (gravity.*)
  double static_start = 0.0, static_end = 0.0;  // the standstill used (both 0: none)
  Vec3 gyro_std = Vec3::Zero();   // per-sample standard deviation at rest, rad/s (zero without a standstill)
  Vec3 acc_std = Vec3::Zero();    // m/s²
  double gyro_noise_density = 0.0;  // estimated from gyro_std and the IMU rate, rad/s/√Hz
  double acc_noise_density = 0.0;   // m/s²/√Hz
  std::string heading_source;     // "dual_antenna" | "motion" (the fit of GNSS and IMU)
  bool nonholonomic_fit = false;  // the fit assumed motion along body x (its yaw is the course's)
  std::string start;              // "standstill" | "moving"
  std::string standstill_witness;  // "wheels" | "gnss_velocity" | "gnss_position" | "" (no standstill)
  double yaw_sigma = 0.0, tilt_sigma = 0.0;  // rad, of P0
  double window_start = 0.0;      // the fit's first epoch
  NavState fit_start;             // the fit's state there (at window_start) and its covariance
  Mat15 fit_start_P = Mat15::Identity();
  std::vector<ImuSample> fit_imu;  // the fit's IMU samples (body axes), from window_start to x0.t
  // Everything since the first fix, for the backward runs before the initialisation
  // (solver/pre_init_backward.h): the IMU samples and the fixes before x0.t.
  std::vector<ImuSample> pre_init_imu;
  std::vector<GnssMeasurement> pre_init_fixes;
  double chi2_per_dof = 0.0, inflation = 1.0, runner_up_delta_chi2 = 0.0;
};

// Whether an alignment fit may start the estimators (docs/estimators.md): its yaw σ within
// max_attitude_sigma and its roll/pitch σ within max_tilt_sigma, no other yaw explaining the window nearly as
// well (Δχ² above the χ²(1) 99.99 % quantile times the fit's inflation); or, once the window is as long as it
// gets (window_full), a settled fit: yaw σ up to 30°, roll/pitch σ up to 5°, the other yaw ruled out at the
// plain quantile.
bool FitStartsEstimators(const AlignmentFit& a, bool window_full, double max_attitude_sigma, double max_tilt_sigma);

// A state at rest before the initialisation completes (Initializer::RestStates): 1-σ about the world axes.
struct RestState {
  NavState x;
  Vec3 sigma_p = Vec3::Zero(), sigma_v = Vec3::Zero(), sigma_att = Vec3::Zero();
};

class Initializer {
 public:
  // The sensors, its own settings (init.*) and the standstill detector's (standstill.*).
  Initializer(const SensorOptions& sensors, const InitOptions& init, const StandstillOptions& standstill,
              const EarthModel& earth);
  // The flat Earth with constant gravity of magnitude g_norm.
  Initializer(const SensorOptions& sensors, const InitOptions& init, const StandstillOptions& standstill,
              double g_norm)
      : Initializer(sensors, init, standstill, EarthModel(g_norm)) {}

  // In time order; GNSS in w.
  void AddImu(const ImuSample& imu);
  void AddWheel(const WheelMeasurement& wheel);
  void AddGnss(const GnssMeasurement& gnss);
  void AddGnssVelocity(const GnssVelocityMeasurement& gnss_velocity);

  bool done() const { return result_.has_value(); }
  const InitResult& result() const { return *result_; }
  // The states at rest after `after` and not after the newest IMU sample, one per IMU sample, appended to
  // *out in time order: while standing (the detector's window back-dated to where the quiet began), from
  // the standstill's first fix on; none before the initialisation completes otherwise.
  void RestStates(double after, std::vector<RestState>* out) const;
  // Why initialisation has not completed, for the error message at the end of a log.
  std::string Diagnosis() const;

 private:
  struct Standstill {
    StaticSummary summary;
    Vec3 gyro_sum = Vec3::Zero(), acc_sum = Vec3::Zero(), gyro_sq = Vec3::Zero(), acc_sq = Vec3::Zero();
    StandstillDetector::Witness witness = StandstillDetector::Witness::kNone;
    std::vector<GnssMeasurement> fixes;  // the antenna did not move: a few suffice
  };
  void TrackStandstill(const ImuSample& imu);
  void CloseStandstill();
  // Adds (sign +1) or removes (−1) a sample from the current standstill's sums.
  void Accumulate(const ImuSample& imu, double sign);
  static void Summarize(Standstill* st);
  void Prune(double t);
  // The window for the fit ending at the fix; false (and last_problem_) when there is nothing to fit yet.
  // *full: the window is as long as the IMU's noise allows (it slides from now on).
  bool BuildWindow(const GnssMeasurement& fix, AlignmentInput* in, bool* from_standstill, bool* full);
  bool Moved(const AlignmentInput& in) const;
  bool Acceptable(const AlignmentFit& a, bool window_full);
  void TryStandingWithHeading(const GnssMeasurement& fix);
  void TryFit(const GnssMeasurement& fix);
  void Finish(const AlignmentFit& a, const GnssMeasurement& fix, const std::optional<Standstill>& standstill,
              std::vector<ImuSample> fit_imu);

  SensorOptions sensors_;
  InitOptions init_options_;
  StandstillOptions standstill_options_;
  EarthModel earth_;
  AlignmentOptions align_options_;
  StandstillDetector detector_;
  std::deque<ImuSample> imu_;  // since the last IMU gap, at most the longest window
  std::deque<GnssMeasurement> fixes_;
  std::deque<GnssVelocityMeasurement> gnss_velocities_;
  std::deque<WheelMeasurement> wheels_;
  double first_time_ = -1.0;
  // The IMU samples and fixes of the last init.max_wait_s plus the longest window: InitResult's pre_init_*
  // (from the first fix on).
  std::deque<ImuSample> history_imu_;
  std::deque<GnssMeasurement> history_fixes_;
  std::optional<Standstill> standing_;  // the current standstill
  std::optional<Standstill> last_standstill_;  // the latest one that ended
  double last_attempt_ = -1e300;
  std::string last_problem_;
  std::optional<InitResult> result_;
};

}  // namespace gins
