#include "solver/estimator.h"

#include <algorithm>
#include <cmath>

#include "core/so3.h"

namespace gins {

namespace {
constexpr size_t kMaxListedTimes = 100;
// Re-initialisation from GNSS.
constexpr double kResetPosSigma = 1.0;        // m, added to the fix's σ
constexpr double kResetVelSigma = 1.0;        // m/s, velocity from two fixes
constexpr double kResetKeptVelSigma = 2.0;    // m/s, velocity kept from the diverged estimate
constexpr double kResetMaxFixInterval = 2.0;  // s, longest interval of two fixes giving the velocity
constexpr double kResetMinYawSigma = 2.0 * kDegToRad;  // a diverged estimate may have a wrong yaw
}  // namespace

bool ResetPositionFromFix(const GnssMeasurement& m, const std::optional<GnssMeasurement>& prev_fix,
                          const EstimatorOptions& options, NavState* x, Eigen::Ref<MatX> P) {
  x->t = m.t;
  x->p_wb = m.p_w - x->q_wb * options.gnss.lever_b;
  bool have_velocity = false;
  if (prev_fix && m.t - prev_fix->t > 0.0 && m.t - prev_fix->t <= kResetMaxFixInterval) {
    x->v_w = (m.p_w - prev_fix->p_w) / (m.t - prev_fix->t);
    have_velocity = true;
  }
  // A kept velocity keeps the σ it had (a long coast's is large), at least kResetKeptVelSigma.
  const double kept_sigma_v = std::sqrt(P.block<3, 3>(nav::kV, nav::kV).diagonal().maxCoeff());
  for (int k : {nav::kP, nav::kV}) {
    P.middleRows(k, 3).setZero();
    P.middleCols(k, 3).setZero();
  }
  // Well inside watchdog.max_position_sigma_m, or the next check would reset again.
  const double cap = 0.25 * options.watchdog.max_position_sigma;
  const double sigma_p = std::min(kResetPosSigma, cap);
  P.block<3, 3>(nav::kP, nav::kP).diagonal() = m.sigma_w.cwiseAbs2() + Vec3::Constant(sigma_p * sigma_p);
  const double sigma_v =
      std::min(have_velocity ? kResetVelSigma : std::max(kResetKeptVelSigma, std::isfinite(kept_sigma_v) ? kept_sigma_v : 0.0), cap);
  P.block<3, 3>(nav::kV, nav::kV).diagonal().setConstant(sigma_v * sigma_v);
  // A vehicle's attitude is known at least as well as the fallback's (level within 0.22 rad, yaw within
  // 1 rad): a larger attitude σ (a long coast's) is reset to that, decorrelated from the rest, so the next
  // fixes are not read as tilt.
  const Mat3 fallback = FallbackCovariance(options).block<3, 3>(nav::kTheta, nav::kTheta);
  const Vec3 att_var = P.block<3, 3>(nav::kTheta, nav::kTheta).diagonal();
  if (!(att_var.array() <= fallback.diagonal().array()).all()) {
    const Vec3 capped = att_var.cwiseMin(fallback.diagonal());
    P.middleRows(nav::kTheta, 3).setZero();
    P.middleCols(nav::kTheta, 3).setZero();
    P.block<3, 3>(nav::kTheta, nav::kTheta).diagonal() = capped.array().isFinite().select(capped, fallback.diagonal());
  }
  const Vec3 z_b = x->q_wb.conjugate() * Vec3::UnitZ();
  const double yaw_var = z_b.dot(P.block<3, 3>(nav::kTheta, nav::kTheta) * z_b);
  const double min_yaw_var = kResetMinYawSigma * kResetMinYawSigma;
  if (yaw_var < min_yaw_var) P.block<3, 3>(nav::kTheta, nav::kTheta) += (min_yaw_var - yaw_var) * z_b * z_b.transpose();
  return have_velocity;
}

Quat FallbackAttitude(const GnssMeasurement& m, const EstimatorOptions& options) {
  return QuatFromYaw(m.heading_valid ? m.yaw_G - options.gnss.mount_yaw : 0.0);
}

Mat15 FallbackCovariance(const EstimatorOptions& options) {
  Mat15 P = Mat15::Zero();
  P.block<3, 3>(nav::kTheta, nav::kTheta).diagonal() << 0.05, 0.05, 1.0;
  P.block<3, 3>(nav::kBg, nav::kBg).diagonal().setConstant(std::pow(options.imu.init_gyro_bias_sigma, 2));
  P.block<3, 3>(nav::kBa, nav::kBa).diagonal().setConstant(std::pow(options.imu.init_acc_bias_sigma, 2));
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

void ImuGapLog::Add(double last_sample, double next_sample) {
  ++count_;
  if (times_.size() < kMaxListedTimes) times_.emplace_back(last_sample, next_sample);
}

void ImuGapLog::ToJson(nlohmann::json* j) const {
  (*j)["imu_gaps"] = count_;
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
  return {{"resets", resets}, {"count", count_}};
}

}  // namespace gins
