#include "solver/estimator_common.h"

#include <algorithm>
#include <cmath>

#include "core/chi2.h"
#include "core/so3.h"
#include "solver/summary_keys.h"

namespace gins {

namespace {
constexpr size_t kMaxListedTimes = 100;
// Re-initialisation from GNSS.
constexpr double kResetPosSigma = 1.0;        // m, added to the fix's σ
constexpr double kResetVelSigma = 1.0;        // m/s, velocity from two fixes
constexpr double kResetKeptVelSigma = 2.0;    // m/s, velocity kept from the diverged estimate
constexpr double kResetMaxFixInterval = 2.0;  // s, longest interval of two fixes giving the velocity
constexpr double kResetMinYawSigma = 2.0 * kDegToRad;  // a diverged estimate may have a wrong yaw
// Beyond this yaw 1-σ the error-state model's linearisation no longer holds (a 20° yaw error puts a third
// of the speed across the track): such a yaw is lost, not kept.
constexpr double kResetLostYawSigma = 20.0 * kDegToRad;

bool RecentFix(const GnssMeasurement& m, const std::optional<GnssMeasurement>& prev_fix) {
  return prev_fix && m.t - prev_fix->t > 0.0 && m.t - prev_fix->t <= kResetMaxFixInterval;
}

// Variance of the yaw (rotation about world up) in a body-frame attitude covariance.
double YawVariance(const Quat& q_wb, const Eigen::Ref<const MatX>& P) {
  const Vec3 z_b = q_wb.conjugate() * Vec3::UnitZ();
  return z_b.dot(P.block<3, 3>(nav::kTheta, nav::kTheta) * z_b);
}

bool YawLost(const Quat& q_wb, const Eigen::Ref<const MatX>& P) {
  return !(YawVariance(q_wb, P) <= kResetLostYawSigma * kResetLostYawSigma);  // NaN too
}

bool HeadingUsable(const GnssMeasurement& m, const GnssOptions& gnss) {
  return m.heading_valid && gnss.use_heading && std::isfinite(m.yaw_G);
}

// The course of the two fixes as the yaw of a car's body x axis, with its 1-σ; none when the fixes are not
// recent or the vehicle moves too slowly between them for a course within about 20°.
std::optional<std::pair<double, double>> CourseOf(const GnssMeasurement& m,
                                                  const std::optional<GnssMeasurement>& prev_fix) {
  if (!RecentFix(m, prev_fix)) return std::nullopt;
  const double dt = m.t - prev_fix->t;
  const Vec3 v = (m.p_w - prev_fix->p_w) / dt;
  const double speed = v.head<2>().norm();
  const double sigma_v = std::hypot(m.sigma_w.head<2>().maxCoeff(), prev_fix->sigma_w.head<2>().maxCoeff()) / dt;
  if (!(speed > 3.0 * sigma_v)) return std::nullopt;
  return std::make_pair(std::atan2(v.y(), v.x()), sigma_v / speed);
}

}  // namespace

bool ResetWaitsForCourse(const GnssMeasurement& m, const std::optional<GnssMeasurement>& prev_fix,
                         const SensorOptions& options, const NavState& x, const Eigen::Ref<const MatX>& P,
                         bool waiting) {
  if (!options.vehicle.nonholonomic || HeadingUsable(m, options.gnss) || CourseOf(m, prev_fix)) return false;
  if (waiting) return prev_fix && m.t - prev_fix->t < kResetMaxFixInterval;
  return x.q_wb.coeffs().allFinite() && YawLost(x.q_wb, P);
}

bool CourseWait::Hold(const GnssMeasurement& m, std::optional<GnssMeasurement>* prev_fix,
                      const SensorOptions& options, const NavState& x, const Eigen::Ref<const MatX>& P) {
  if (!ResetWaitsForCourse(m, *prev_fix, options, x, P, waiting_)) return false;
  if (!waiting_) *prev_fix = m;
  waiting_ = true;
  return true;
}

FixVerdict WatchdogVerdict(const GnssMeasurement& m, bool finite, double sigma_p, const SensorOptions& options,
                           const WatchdogOptions& watchdog, const NavState& x, const Eigen::Ref<const MatX>& P,
                           CourseWait* wait, std::optional<GnssMeasurement>* prev_fix) {
  if (!watchdog.enabled) return FixVerdict::kUse;
  if (!(wait->waiting() || !finite || sigma_p > watchdog.max_position_sigma)) return FixVerdict::kUse;
  // A lost yaw waits for a later fix's course rather than being kept (ResetWaitsForCourse).
  return finite && wait->Hold(m, prev_fix, options, x, P) ? FixVerdict::kHeld : FixVerdict::kReset;
}

std::string Describe(const FixReset& r) {
  std::string s = r.velocity_from_fixes ? "velocity from the last two fixes" : "velocity kept";
  if (std::string(r.yaw) == "heading") s += ", yaw from the dual-antenna heading";
  if (std::string(r.yaw) == "course") s += ", yaw from the course of the two fixes";
  return s;
}

FixReset ResetPositionFromFix(const GnssMeasurement& m, const std::optional<GnssMeasurement>& prev_fix,
                              const SensorOptions& options, const WatchdogOptions& watchdog, NavState* x,
                              Eigen::Ref<MatX> P, bool yaw_lost_before) {
  FixReset result;
  // A lost yaw is replaced before the lever arm is applied: the arm turns with the body.
  const bool yaw_lost = yaw_lost_before || YawLost(x->q_wb, P);
  std::optional<std::pair<double, double>> yaw;  // the new yaw and its 1-σ
  if (yaw_lost && HeadingUsable(m, options.gnss)) {
    yaw = std::make_pair(m.yaw_G - options.gnss.mount_yaw, m.sigma_yaw);
    result.yaw = "heading";
  } else if (yaw_lost && options.vehicle.nonholonomic) {
    yaw = CourseOf(m, prev_fix);
    if (yaw) result.yaw = "course";
  }
  if (yaw) {
    // Turn the body about world up onto the new yaw (roll and pitch kept); the attitude covariance becomes
    // the level part it had (at most the fallback's) and the new yaw's variance, uncorrelated with the rest.
    // A kept velocity turns with it: the car still moves along its body axis at the speed it had.
    const Quat turn = QuatFromYaw(yaw->first - YawOfXAxis<double>(x->q_wb.toRotationMatrix()));
    x->q_wb = (turn * x->q_wb).normalized();
    x->v_w = turn * x->v_w;
    const Mat3 fallback = FallbackCovariance(options.imu).block<3, 3>(nav::kTheta, nav::kTheta);
    const Mat3 P_att = P.block<3, 3>(nav::kTheta, nav::kTheta);
    const double level_var = std::min(std::max(P_att(0, 0), P_att(1, 1)), fallback(0, 0));
    const Vec3 z_b = x->q_wb.conjugate() * Vec3::UnitZ();
    const double yaw_var = std::pow(std::max(yaw->second, kResetMinYawSigma), 2);
    P.middleRows(nav::kTheta, 3).setZero();
    P.middleCols(nav::kTheta, 3).setZero();
    P.block<3, 3>(nav::kTheta, nav::kTheta) = (std::isfinite(level_var) ? level_var : fallback(0, 0)) *
                                                   (Mat3::Identity() - z_b * z_b.transpose()) +
                                               yaw_var * z_b * z_b.transpose();
  }
  x->t = m.t;
  x->p_wb = m.p_w - x->q_wb * options.gnss.lever_b;
  bool have_velocity = false;
  if (RecentFix(m, prev_fix)) {
    x->v_w = (m.p_w - prev_fix->p_w) / (m.t - prev_fix->t);
    have_velocity = true;
  }
  result.velocity_from_fixes = have_velocity;
  // A kept velocity keeps the σ it had (a long coast's is large), at least kResetKeptVelSigma.
  const double kept_sigma_v = std::sqrt(P.block<3, 3>(nav::kV, nav::kV).diagonal().maxCoeff());
  for (int k : {nav::kP, nav::kV}) {
    P.middleRows(k, 3).setZero();
    P.middleCols(k, 3).setZero();
  }
  // Well inside watchdog.max_position_sigma_m, or the next check would reset again.
  const double cap = 0.25 * watchdog.max_position_sigma;
  const double sigma_p = std::min(kResetPosSigma, cap);
  P.block<3, 3>(nav::kP, nav::kP).diagonal() = m.sigma_w.cwiseAbs2() + Vec3::Constant(sigma_p * sigma_p);
  const double sigma_v =
      std::min(have_velocity ? kResetVelSigma : std::max(kResetKeptVelSigma, std::isfinite(kept_sigma_v) ? kept_sigma_v : 0.0), cap);
  P.block<3, 3>(nav::kV, nav::kV).diagonal().setConstant(sigma_v * sigma_v);
  // A vehicle's attitude is known at least as well as the fallback's (level within 0.22 rad, yaw within
  // 1 rad): a larger attitude σ (a long coast's) is reset to that, decorrelated from the rest, so the next
  // fixes are not read as tilt.
  const Mat3 fallback = FallbackCovariance(options.imu).block<3, 3>(nav::kTheta, nav::kTheta);
  const Vec3 att_var = P.block<3, 3>(nav::kTheta, nav::kTheta).diagonal();
  if (!(att_var.array() <= fallback.diagonal().array()).all()) {
    const Vec3 capped = att_var.cwiseMin(fallback.diagonal());
    P.middleRows(nav::kTheta, 3).setZero();
    P.middleCols(nav::kTheta, 3).setZero();
    P.block<3, 3>(nav::kTheta, nav::kTheta).diagonal() = capped.array().isFinite().select(capped, fallback.diagonal());
  }
  const Vec3 z_b = x->q_wb.conjugate() * Vec3::UnitZ();
  const double yaw_var = YawVariance(x->q_wb, P);
  const double min_yaw_var = kResetMinYawSigma * kResetMinYawSigma;
  if (yaw_var < min_yaw_var) P.block<3, 3>(nav::kTheta, nav::kTheta) += (min_yaw_var - yaw_var) * z_b * z_b.transpose();
  return result;
}

Quat FallbackAttitude(const GnssMeasurement& m, const GnssOptions& gnss) {
  return QuatFromYaw(m.heading_valid ? m.yaw_G - gnss.mount_yaw : 0.0);
}

Mat15 FallbackCovariance(const ImuOptions& imu) {
  Mat15 P = Mat15::Zero();
  P.block<3, 3>(nav::kTheta, nav::kTheta).diagonal() << 0.05, 0.05, 1.0;
  P.block<3, 3>(nav::kBg, nav::kBg).diagonal().setConstant(std::pow(imu.init_gyro_bias_sigma, 2));
  P.block<3, 3>(nav::kBa, nav::kBa).diagonal().setConstant(std::pow(imu.init_acc_bias_sigma, 2));
  return P;
}

void GateInflation::Rejected(double t, const Vec3& innovation, const Mat3& S, double gate) {
  bool agrees = false;
  if (run_) {
    const Vec3 d = innovation - last_innovation_;
    const Mat3 C = S + last_S_;
    const Eigen::LLT<Mat3> llt(C);
    agrees = llt.info() == Eigen::Success && d.dot(llt.solve(d)) <= gate;
  }
  if (!agrees) {
    run_ = true;
    start_ = t;
  }
  // Capped far beyond any useful doubt (2^60), so the factor stays finite on any log.
  factor_ = std::exp2(std::min(t - start_, 60.0));
  last_innovation_ = innovation;
  last_S_ = S;
}

GateConsistency::GateConsistency(double gate_probability, int dof) {
  median_ = Chi2Quantile(0.5, dof);
  bounds_.fill(HUGE_VAL);
  if (!(gate_probability > 0.0)) return;  // no gate: nothing to scale
  for (int n = kMinFixes; n <= kFixes; ++n) {
    // The sample median (the (n/2+1)-th smallest) of n χ² exceeds q when at least n − n/2 of them do:
    // a binomial tail in u = P(χ² > q), which grows with u. u is found where the tail is
    // 1 − gate_probability, by bisection.
    const auto tail = [n](double u) {
      double sum = 0.0;
      for (int k = n - n / 2; k <= n; ++k) {
        sum += std::exp(std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0) + k * std::log(u) +
                        (n - k) * std::log1p(-u));
      }
      return sum;
    };
    double lo = 0.0, hi = 0.5;
    for (int i = 0; i < 60; ++i) {
      const double u = 0.5 * (lo + hi);
      (tail(u) > 1.0 - gate_probability ? hi : lo) = u;
    }
    bounds_[n] = Chi2Quantile(1.0 - 0.5 * (lo + hi), dof);
  }
}

void GateConsistency::Add(double chi2) {
  if (!std::isfinite(chi2)) return;
  recent_[next_] = chi2;
  next_ = (next_ + 1) % kFixes;
  count_ = std::min(count_ + 1, kFixes);
  if (count_ < kMinFixes) return;
  std::array<double, kFixes> sorted = recent_;
  const auto mid = sorted.begin() + count_ / 2;
  std::nth_element(sorted.begin(), mid, sorted.begin() + count_);
  scale_ = *mid > bounds_[count_] ? *mid / median_ : 1.0;
  max_scale_ = std::max(max_scale_, scale_);
}

void ImuGapLog::Add(double last_sample, double next_sample) {
  ++count_;
  if (times_.size() < kMaxListedTimes) times_.emplace_back(last_sample, next_sample);
}

void ImuGapLog::ToJson(nlohmann::json* j) const {
  (*j)[summary_keys::kImuGaps] = count_;
  (*j)["imu_gap_times"] = nlohmann::json::array();
  for (const auto& [a, b] : times_) (*j)["imu_gap_times"].push_back({a, b});
}

void MeasurementCounts::Reject(const std::string& reason, double t) {
  ++rejected[reason];
  if (rejected_times.size() < kMaxListedTimes) rejected_times.push_back(t);
}

nlohmann::json MeasurementCounts::ToJson() const {
  nlohmann::json j;
  uint64_t offered = used;
  j["used"] = used;
  j["rejected"] = nlohmann::json::object();
  for (const auto& [k, v] : rejected) {
    j["rejected"][k] = v;
    offered += v;
  }
  j["offered"] = offered;
  j["rejected_times"] = rejected_times;
  return j;
}

bool GnssWatchdog::Watch(double t, bool accepted) {
  if (accepted) {
    Clear();
    return false;
  }
  if (first_reject_t_ < 0.0) first_reject_t_ = t;
  ++rejects_;
  return options_.enabled && rejects_ >= kMinRejects && t - first_reject_t_ >= options_.max_reject;
}

void GnssWatchdog::Reset(double t, const std::string& reason) {
  Clear();
  ++count_;
  if (resets_.size() < kMaxListedTimes) resets_.push_back({t, reason});
}

nlohmann::json GnssWatchdog::ToJson() const {
  nlohmann::json resets = nlohmann::json::array();
  for (const Event& r : resets_) resets.push_back({{"time", r.t}, {"reason", r.reason}});
  return {{"resets", resets}, {summary_keys::kWatchdogCount, count_}};
}

nlohmann::json TimeOffsetJson(const GnssOptions& gnss, double td, double sigma) {
  return {{"estimated", gnss.estimate_time_offset}, {"final_s", gnss.time_offset + td}, {"final_sigma_s", sigma}};
}

}  // namespace gins
