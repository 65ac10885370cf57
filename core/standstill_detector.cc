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

Vec3 StandstillDetector::WindowMeanAcc() const {
  Vec3 sum = Vec3::Zero();
  for (const ImuSample& s : imu_) sum += s.acc;
  return imu_.empty() ? sum : Vec3(sum / static_cast<double>(imu_.size()));
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
  AppendSums(imu);
  while (!imu_.empty() && t_ - imu_.front().t > options_.window) {
    const CumulativeSums out = Deviations(imu_.front());
    sq_g_ -= out.g.cwiseAbs2();
    sq_a_ -= out.a.cwiseAbs2();
    cum_before_ = cum_.front();
    cum_.pop_front();
    imu_.pop_front();
    ++removed_;
  }
  if (removed_ >= imu_.size()) Rebase();
  const double keep = std::max(options_.window, 2.0 * wheel_interval_);
  while (!wheels_.empty() && t_ - wheels_.front().t > keep) wheels_.pop_front();
  while (!fixes_.empty() && t_ - fixes_.front().t > kMaxGnssSpan) fixes_.pop_front();
  while (!gnss_velocities_.empty() && t_ - gnss_velocities_.front().t > kMaxGnssSpan) gnss_velocities_.pop_front();
  if (!WindowQuiet()) {
    quiet_since_ = -1.0;
  } else if (quiet_since_ < 0.0) {
    quiet_since_ = imu_.front().t;
  }
}

void StandstillDetector::AddWheel(const WheelMeasurement& wheel) { wheels_.push_back(wheel); }
void StandstillDetector::AddGnss(const GnssMeasurement& fix) { fixes_.push_back(fix); }
void StandstillDetector::AddGnssVelocity(const GnssVelocityMeasurement& vel) { gnss_velocities_.push_back(vel); }

StandstillDetector::CumulativeSums StandstillDetector::Deviations(const ImuSample& s) const {
  return {s.gyro - ref_g_, s.acc - ref_a_};
}

void StandstillDetector::AppendSums(const ImuSample& s) {
  const CumulativeSums d = Deviations(s);
  CumulativeSums c = cum_.empty() ? cum_before_ : cum_.back();
  c.g += d.g;
  c.a += d.a;
  cum_.push_back(c);
  sq_g_ += d.g.cwiseAbs2();
  sq_a_ += d.a.cwiseAbs2();
}

void StandstillDetector::Rebase() {
  // Deviations about a sample of the window keep the variance accurate next to |g|.
  ref_g_ = imu_.empty() ? Vec3::Zero() : imu_.front().gyro;
  ref_a_ = imu_.empty() ? Vec3::Zero() : imu_.front().acc;
  cum_before_ = CumulativeSums{};
  cum_.clear();
  sq_g_.setZero();
  sq_a_.setZero();
  removed_ = 0;
  for (const ImuSample& s : imu_) AppendSums(s);
}

bool StandstillDetector::WindowQuiet() const {
  // A window with a gap, or too short, says nothing.
  if (imu_.size() < 10 || imu_.back().t - imu_.front().t < 0.9 * options_.window) return false;
  const double n = static_cast<double>(imu_.size());
  const Vec3 sg = cum_.back().g - cum_before_.g, sa = cum_.back().a - cum_before_.a;
  const Vec3 var_g = (sq_g_ / n - (sg / n).cwiseAbs2()).cwiseMax(0.0);
  const Vec3 var_a = (sq_a_ / n - (sa / n).cwiseAbs2()).cwiseMax(0.0);
  const Vec3 mean_g = ref_g_ + sg / n, mean_a = ref_a_ + sa / n;
  if (!(var_g.maxCoeff() < options_.max_gyro_std * options_.max_gyro_std &&
        var_a.maxCoeff() < options_.max_acc_std * options_.max_acc_std && mean_g.norm() < kMaxMeanRate &&
        std::abs(mean_a.norm() - g_norm_) < kMaxAccNormError)) {
    return false;
  }
  // A vehicle that starts to move gently is still quiet over the window for a while: the newest part of the
  // window must also agree with its oldest part (means over a fifth of the window each, within half the
  // standard-deviation thresholds). The reference cancels in their difference.
  const size_t k = std::max<size_t>(2, imu_.size() / 5);
  const CumulativeSums& old_end = cum_[k - 1];
  const CumulativeSums& new_start = cum_[imu_.size() - 1 - k];
  const Vec3 old_g = old_end.g - cum_before_.g, old_a = old_end.a - cum_before_.a;
  const Vec3 new_g = cum_.back().g - new_start.g, new_a = cum_.back().a - new_start.a;
  const double kk = static_cast<double>(k);
  return ((new_g - old_g) / kk).cwiseAbs().maxCoeff() < 0.5 * options_.max_gyro_std &&
         ((new_a - old_a) / kk).cwiseAbs().maxCoeff() < 0.5 * options_.max_acc_std;
}

bool StandstillDetector::WheelsPresent() const { return !wheels_.empty(); }

StandstillDetector::State StandstillDetector::GnssVerdict(Witness* witness) const {
  // GNSS velocity: the mean over the quiet stretch against zero.
  if (const std::optional<GnssSpeed> v = MeanGnssVelocity(gnss_velocities_, quiet_since_)) {
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
