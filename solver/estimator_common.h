// What the ESKF and the smoother share beyond the Estimator interface (solver/estimator.h): measurement
// counts, the GNSS watchdog and gate inflation, the IMU-gap and standstill rules, the re-initialisation from
// a fix, the summary's time offset.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/measurements.h"
#include "core/nav_state.h"
#include "core/standstill_detector.h"
#include "solver/estimator_options.h"

namespace gins {

// Counts of one measurement type: used, and rejected by reason; in the summary also "offered", the two
// together (every measurement of the type that reached the estimator's check).
struct MeasurementCounts {
  uint64_t used = 0;
  std::map<std::string, uint64_t> rejected;
  std::vector<double> rejected_times;  // first few, for the summary
  void Reject(const std::string& reason, double t);
  nlohmann::json ToJson() const;
};

// The watchdog's bookkeeping, alike in both estimators: how long every GNSS fix has been rejected, and the
// re-initialisations so far (listed in the summary). What a re-initialisation does is each estimator's own.
class GnssWatchdog {
 public:
  explicit GnssWatchdog(const WatchdogOptions& options) : options_(options) {}
  // One fix's outcome. True when the estimator should re-initialise from GNSS: at least kMinRejects fixes
  // in a row rejected, over at least watchdog.max_reject_s (and the watchdog enabled).
  bool Watch(double t, bool accepted);
  // A re-initialisation at t happened: the rejection streak starts again.
  void Reset(double t, const std::string& reason);
  void Clear() { first_reject_t_ = -1.0, rejects_ = 0; }
  nlohmann::json ToJson() const;  // {"resets": [{"time", "reason"}...], "count"}

 private:
  static constexpr int kMinRejects = 3;
  struct Event {
    double t;
    std::string reason;
  };
  WatchdogOptions options_;
  double first_reject_t_ = -1.0;  // first rejected fix since the last accepted one (< 0: none)
  int rejects_ = 0;
  std::vector<Event> resets_;     // the first few
  uint64_t count_ = 0;
};

// Re-acquiring GNSS after an outage by design. A run of rejected fixes that agree with one another says the
// estimate, not the fixes, is off: an overconfident covariance (an IMU noisier than its configuration,
// vibration) would otherwise reject every returning fix until the watchdog. While such a run lasts, the gate
// doubts the predicted covariance more and more: by a factor 2^(seconds since the run began), whatever the
// fix rate. A drifted estimate then re-acquires within a few fixes; an outlier burst metres away from an
// estimate that knows its place to centimetres would need a factor of 1e5-1e6, more seconds than the
// watchdog's max_reject_s, and stays out. Rejected fixes that disagree with one another (scattered
// outliers) restart the run. Both estimators use it for GNSS positions.
class GateInflation {
 public:
  // The factor the next gate multiplies the predicted covariance by (1 outside a run).
  double factor() const { return factor_; }
  // A fix at t was rejected: its innovation ν (measured − predicted) and the innovation covariance S the
  // gate used without inflation; gate: the χ² bound for two such innovations to agree.
  void Rejected(double t, const Vec3& innovation, const Mat3& S, double gate);
  void Accepted() { run_ = false, factor_ = 1.0; }
  // How many fixes were accepted under a factor > 1 (re-acquisitions), for the summary.
  uint64_t reacquired() const { return reacquired_; }
  void CountReacquired() { ++reacquired_; }

 private:
  bool run_ = false;
  double start_ = 0.0;
  Vec3 last_innovation_ = Vec3::Zero();
  Mat3 last_S_ = Mat3::Identity();
  double factor_ = 1.0;
  uint64_t reacquired_ = 0;
};

// The GNSS position gate's scale, learnt from the fixes it accepts. A receiver's stated σ is its precision,
// and an IMU's stated noise its noise at rest: on a hand-held unit or a vibrating mount the fixes and the
// prediction may disagree by several times what their covariances say on every fix, not on a few. Gated
// at the stated covariances, half the good fixes are then rejected and each rejection lets the estimate
// drift until the next is rejected too. Over the last kFixes accepted fixes (from kMinFixes on), the
// median of their χ² (with the predicted covariance undoubted) is compared with χ²(dof)'s median: when it
// is above what consistent fixes give with probability 1 − gnss.gate_probability, the gate's bound is
// multiplied by the ratio of the two medians (the innovations' spread against the stated one), else by 1.
// The median ignores the odd outlier that passes; a burst of outliers passes no gate and teaches nothing.
// The update keeps the stated noise: only which fixes are outliers changes.
class GateConsistency {
 public:
  GateConsistency(double gate_probability, int dof);
  // A fix accepted at the unscaled, undoubted gate's χ² = chi2.
  void Add(double chi2);
  double scale() const { return scale_; }
  double max_scale() const { return max_scale_; }

 private:
  static constexpr int kFixes = 21, kMinFixes = 5;
  std::array<double, kFixes> recent_{};
  int count_ = 0, next_ = 0;
  double median_ = 1.0;  // χ²(dof)'s median
  // The sample median's bound for n consistent fixes, by n (+∞ below kMinFixes, or without a gate).
  std::array<double, kFixes + 1> bounds_{};
  double scale_ = 1.0, max_scale_ = 1.0;
};

// IMU gaps longer than imu.max_gap_s, counted and the first few listed (summary: imu_gaps, imu_gap_times).
class ImuGapLog {
 public:
  void Add(double last_sample, double next_sample);
  void ToJson(nlohmann::json* j) const;

 private:
  uint64_t count_ = 0;
  std::vector<std::pair<double, double>> times_;  // [last sample, next sample]
};

// Across an IMU gap longer than imu.max_gap_s both estimators coast (no rotation, no acceleration) with the
// uncertainty of an unknown motion (Eskf::CoastCovariance, Smoother::IntegrateTo), taken as random walks so
// that a gap cut into steps (by the fixes inside it) grows as much as one step; their σ grow with the square
// root of the gap: the velocity's by 2 m/s in 1 s (6 m/s in 10 s, 15 m/s in 60 s: a car's speed changes),
// the yaw's by 10° in 1 s (77° in 60 s: it may turn any way), roll and pitch by 0.5° in 1 s (4° in 60 s: a
// road's grade and banking).
constexpr double kImuGapAccDensity = 2.0;                 // m/s² per √(1/s): σ_v = 2 m/s·√(T/1 s)
constexpr double kImuGapYawDensity = 10.0 * kDegToRad;    // rad per √s
constexpr double kImuGapTiltDensity = 0.5 * kDegToRad;    // rad per √s

// A standstill detection is ignored while the estimate moves faster than standstill.max_speed_m_s: a quiet
// IMU at constant speed is not a stop.
inline bool StandstillPlausible(const Vec3& v_w, const StandstillOptions& options) {
  return !(v_w.norm() > options.max_speed);
}

// At a standstill the gyro reads its bias plus the Earth's rate (the zero-rate check, alike in both
// estimators): the residual bg + R_wbᵀ·ω_ie − the mean gyro reading over T seconds, 1-σ 2·N_g/√T per axis
// (N_g: imu.gyro_noise), gated at this probability with the bias's σ. Standing is not the same as not
// turning: a vehicle may turn in place, or settle for seconds after it stops; the gate then keeps its
// rotation free (the translation still stands).
constexpr double kZeroRateGateProbability = 0.9999;
inline double ZeroRateSigma(double gyro_noise_density, double T) { return 2.0 * gyro_noise_density / std::sqrt(T); }

// A standstill nothing witnesses (StandstillMeasurement::witnessed false: no wheels, no GNSS) is not taken
// while the estimate accelerates: smooth braking is as quiet to an IMU as rest, and a zero velocity taken
// a fraction of a second before the stop moves a long outage's position by metres through its correlation
// with the velocity. The window's mean specific force, less the bias, rotated into w and with gravity
// added, must be zero horizontally within 3 σ: the tilt's σ times g, the accelerometer bias's σ and the
// noise of the window's mean.
inline bool AcceleratingWithoutWitness(const StandstillMeasurement& m, const NavState& x, const Vec3& g_w,
                                       double sigma_tilt, double sigma_ba, double acc_noise_density) {
  if (m.witnessed || !(m.window_s > 0.0)) return false;
  const Vec3 a_w = x.q_wb * (m.acc_mean_b - x.ba) + g_w;
  const double g = g_w.norm();
  const double var = g * g * sigma_tilt * sigma_tilt + sigma_ba * sigma_ba +
                     acc_noise_density * acc_noise_density / m.window_s;
  return a_w.head<2>().squaredNorm() > 9.0 * var;
}

// When the state is no longer finite nothing is left to keep: a level attitude (the yaw of the dual-antenna
// heading if the fix has one) and zero biases, with this covariance in NavState tangent order: attitude
// 1-σ 0.22 rad in roll and pitch and 1 rad in yaw, biases at their initial σ (imu.init_*_bias_sigma);
// position and velocity come from the fix (ResetPositionFromFix).
Quat FallbackAttitude(const GnssMeasurement& m, const GnssOptions& gnss);
Mat15 FallbackCovariance(const ImuOptions& imu);

// summary.json's "time_offset" of an estimator: whether it is estimated, the stated gnss.time_offset_s plus
// the estimated part td (s), and td's 1-σ (0 when held).
nlohmann::json TimeOffsetJson(const GnssOptions& gnss, double td, double sigma);

// The watchdog's re-initialisation from a GNSS fix m, alike in both estimators: position from the fix
// through the lever arm, velocity from the previous fix when it is recent (else kept), and both with a fresh
// covariance, uncorrelated with the rest; the yaw variance is raised to at least (2°)², since a
// diverged estimate may have a wrong yaw. P is the covariance in NavState tangent order (its first 15 rows
// and columns; more, e.g. the ESKF's gravity and scale, are left but decorrelated from δp and δv).
// When the yaw is lost (its 1-σ beyond 20°, where the linearisation fails: a long coast, e.g. a logger
// pause), it is not kept: it comes from the fix's dual-antenna heading, else, for a car
// (vehicle.nonholonomic: it drives along its body x axis), from the course of the two fixes, as a moving
// start would take it.
struct FixReset {
  bool velocity_from_fixes = false;
  const char* yaw = "kept";  // "kept" | "heading" | "course"
};
// `yaw_lost`: the estimator found the yaw lost at an earlier fix and waited for this one
// (ResetWaitsForCourse); the updates in between may have shrunk its variance, not made it right.
FixReset ResetPositionFromFix(const GnssMeasurement& m, const std::optional<GnssMeasurement>& prev_fix,
                              const SensorOptions& options, const WatchdogOptions& watchdog, NavState* x,
                              Eigen::Ref<MatX> P,
                              bool yaw_lost = false);
// A reset at m would keep a lost yaw that a later fix can give (ResetPositionFromFix): the estimator holds
// m and waits instead, for the first fix whose course from m is within about 20° (a second on a 1 Hz RTK
// receiver; a few fixes at 5-20 Hz with metre-level noise), at most 2 s; then it resets with yaw_lost set.
// `waiting`: prev_fix is the fix held (the call decides whether to wait on). P as above, at m's time.
bool ResetWaitsForCourse(const GnssMeasurement& m, const std::optional<GnssMeasurement>& prev_fix,
                         const SensorOptions& options, const NavState& x, const Eigen::Ref<const MatX>& P,
                         bool waiting = false);
// The log line's words for a reset.
std::string Describe(const FixReset& r);

// The wait of ResetWaitsForCourse, alike in both estimators. Hold: whether the reset due at fix m waits
// (the first fix held in *prev_fix: the course starts there). Take, at the reset: whether it waited (the yaw
// was lost), ending the wait.
class CourseWait {
 public:
  bool waiting() const { return waiting_; }
  bool Hold(const GnssMeasurement& m, std::optional<GnssMeasurement>* prev_fix, const SensorOptions& options,
            const NavState& x, const Eigen::Ref<const MatX>& P);
  bool Take() {
    const bool waited = waiting_;
    waiting_ = false;
    return waited;
  }

 private:
  bool waiting_ = false;
};

// The watchdog's decision at fix m, before the fix is used, alike in both estimators: the estimate is lost
// when it is not finite or its position 1-σ (sigma_p, m) is beyond watchdog.max_position_sigma, and stays
// lost while a reset waits for a course (CourseWait). kUse: the fix is used as usual; kHeld: the reset waits,
// m held for its course; kReset: the estimator re-initialises from m. Always kUse with the watchdog off.
enum class FixVerdict { kUse, kHeld, kReset };
FixVerdict WatchdogVerdict(const GnssMeasurement& m, bool finite, double sigma_p, const SensorOptions& options,
                           const WatchdogOptions& watchdog, const NavState& x, const Eigen::Ref<const MatX>& P, CourseWait* wait,
                           std::optional<GnssMeasurement>* prev_fix);

}  // namespace gins
