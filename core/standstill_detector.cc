#include "core/standstill_detector.h"

#include <algorithm>
#include <cmath>

#include "core/chi2.h"

namespace gins {
namespace {

constexpr double kMaxMeanRate = 1.0 * kDegToRad;  // rad/s: far above any MEMS bias, far below a turn
constexpr double kMaxAccNormError = 0.3;          // m/s²
// How far back the GNSS witnesses look (the quiet stretch, at most this long).
constexpr double kMaxGnssSpan = 30.0;  // s
// A zero speed is consistent with the GNSS at this probability (χ², 2 dof), ...
constexpr double kZeroSpeedProbability = 0.999;
// ... and the speed's upper bound (estimate + this many σ) is below standstill.max_speed_m_s.
constexpr double kSpeedBoundSigmas = 3.0;

// Whether a horizontal speed estimate says standing, moving or cannot tell.
StandstillDetector::State SpeedVerdict(const GnssSpeed& s, double max_speed) {
  if (GnssShowsMotion(s, kZeroSpeedProbability)) return StandstillDetector::State::kMoving;
  if (s.v.norm() + kSpeedBoundSigmas * s.sigma < max_speed) return StandstillDetector::State::kStanding;
  return StandstillDetector::State::kUndecided;
}

}  // namespace

bool GnssShowsMotion(const GnssSpeed& s, double probability) {
  return s.v.squaredNorm() > Chi2Quantile(probability, 2) * s.sigma * s.sigma;
}

const char* WitnessName(StandstillDetector::Witness w) {
  switch (w) {
    case StandstillDetector::Witness::kWheels:
      return "wheels";
    case StandstillDetector::Witness::kGnssVelocity:
      return "gnss_velocity";
    case StandstillDetector::Witness::kGnssPosition:
      return "gnss_position";
    case StandstillDetector::Witness::kNone:
      break;
  }
  return "none";
}

StandstillDetector::StandstillDetector(const StandstillOptions& options, double g_norm, double wheel_interval)
    : options_(options), g_norm_(g_norm), wheel_interval_(wheel_interval) {}

void StandstillDetector::AddImu(const ImuSample& imu) {
  t_ = imu.t;
  imu_.push_back(imu);
  while (!imu_.empty() && t_ - imu_.front().t > options_.window) imu_.pop_front();
  const double keep = std::max(options_.window, 2.0 * wheel_interval_);
  while (!wheels_.empty() && t_ - wheels_.front().t > keep) wheels_.pop_front();
  while (!fixes_.empty() && t_ - fixes_.front().t > kMaxGnssSpan) fixes_.pop_front();
  while (!gvels_.empty() && t_ - gvels_.front().t > kMaxGnssSpan) gvels_.pop_front();
  if (!WindowQuiet()) {
    quiet_since_ = -1.0;
  } else if (quiet_since_ < 0.0) {
    quiet_since_ = imu_.front().t;
  }
}

void StandstillDetector::AddWheel(const WheelMeasurement& wheel) { wheels_.push_back(wheel); }
void StandstillDetector::AddGnss(const GnssMeasurement& fix) { fixes_.push_back(fix); }
void StandstillDetector::AddGvel(const GvelMeasurement& vel) { gvels_.push_back(vel); }

bool StandstillDetector::WindowQuiet() const {
  // A window with a gap, or too short, says nothing.
  if (imu_.size() < 10 || imu_.back().t - imu_.front().t < 0.9 * options_.window) return false;
  const double n = static_cast<double>(imu_.size());
  // Shifted sums (about the first sample) keep the variance accurate next to |g|.
  const Vec3 g0 = imu_.front().gyro, a0 = imu_.front().acc;
  Vec3 sg = Vec3::Zero(), sa = Vec3::Zero(), sg2 = Vec3::Zero(), sa2 = Vec3::Zero();
  for (const ImuSample& s : imu_) {
    const Vec3 dg = s.gyro - g0, da = s.acc - a0;
    sg += dg;
    sa += da;
    sg2 += dg.cwiseAbs2();
    sa2 += da.cwiseAbs2();
  }
  const Vec3 var_g = (sg2 / n - (sg / n).cwiseAbs2()).cwiseMax(0.0);
  const Vec3 var_a = (sa2 / n - (sa / n).cwiseAbs2()).cwiseMax(0.0);
  const Vec3 mean_g = g0 + sg / n, mean_a = a0 + sa / n;
  if (!(var_g.maxCoeff() < options_.max_gyro_std * options_.max_gyro_std &&
        var_a.maxCoeff() < options_.max_acc_std * options_.max_acc_std && mean_g.norm() < kMaxMeanRate &&
        std::abs(mean_a.norm() - g_norm_) < kMaxAccNormError)) {
    return false;
  }
  // A vehicle that starts to move gently is still quiet over the window for a while: the newest part of the
  // window must also agree with its oldest part (means over a fifth of the window each, within half the
  // standard-deviation thresholds).
  const size_t k = std::max<size_t>(2, imu_.size() / 5);
  Vec3 old_g = Vec3::Zero(), old_a = Vec3::Zero(), new_g = Vec3::Zero(), new_a = Vec3::Zero();
  for (size_t i = 0; i < k; ++i) {
    old_g += imu_[i].gyro;
    old_a += imu_[i].acc;
    new_g += imu_[imu_.size() - 1 - i].gyro;
    new_a += imu_[imu_.size() - 1 - i].acc;
  }
  const double kk = static_cast<double>(k);
  return ((new_g - old_g) / kk).cwiseAbs().maxCoeff() < 0.5 * options_.max_gyro_std &&
         ((new_a - old_a) / kk).cwiseAbs().maxCoeff() < 0.5 * options_.max_acc_std;
}

bool StandstillDetector::WheelsPresent() const { return !wheels_.empty(); }

StandstillDetector::State StandstillDetector::GnssVerdict(Witness* witness) const {
  // GNSS velocity: the mean over the quiet stretch against zero.
  if (const std::optional<GnssSpeed> v = MeanGnssVelocity(gvels_, quiet_since_)) {
    *witness = Witness::kGnssVelocity;
    return SpeedVerdict(*v, options_.max_speed);
  }
  // GNSS positions: a straight line through the fixes of the stretch.
  int n = 0;
  for (const GnssMeasurement& f : fixes_) n += f.t >= quiet_since_ ? 1 : 0;
  // Fewer than two fixes in the stretch (it began just now, or in an outage): the GNSS cannot witness
  // (yet), so the estimators judge by their own speed, as in an outage without encoders. (The initialiser
  // waits for a witnessed standstill.)
  if (n < 2) return State::kQuietUnwitnessed;
  *witness = Witness::kGnssPosition;
  const std::optional<GnssSpeed> line = LineThroughFixes(fixes_, quiet_since_);
  return line ? SpeedVerdict(*line, options_.max_speed) : State::kUndecided;
}

StandstillDetector::State StandstillDetector::Decide() const {
  if (!options_.enabled || quiet_since_ < 0.0) return State::kMoving;
  // Wheels first: they are the cheap test, and while driving they settle it.
  if (WheelsPresent()) {
    for (const WheelMeasurement& w : wheels_) {
      if (!w.standstill) return State::kMoving;
    }
    return State::kStanding;
  }
  Witness unused = Witness::kNone;
  return GnssVerdict(&unused);
}

StandstillDetector::Witness StandstillDetector::witness() const {
  if (WheelsPresent()) return Witness::kWheels;
  if (quiet_since_ < 0.0) return Witness::kNone;
  Witness w = Witness::kNone;
  GnssVerdict(&w);
  return w;
}

bool StandstillDetector::Standing() const {
  const State s = Decide();
  return s == State::kStanding || s == State::kQuietUnwitnessed;
}

}  // namespace gins
