#include "core/clock_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace gins {
namespace {

constexpr long long kKeep = 600;  // s of bins kept per stream

// The whole second nearest t: both streams' bins centred alike (a 1 Hz receiver's accelerations fall on
// whole seconds; floor bins would pair them with IMU seconds half a second off and split a lag).
long long Second(double t) { return static_cast<long long>(std::floor(t + 0.5)); }
// No car accelerates harder; a step between fixes that implies more is an outlier's, not the track's.
constexpr double kMaxAcc = 10.0;  // m/s²


}  // namespace

void ClockOffsetCheck::AddImu(double t, const Vec3& acc_b) {
  if (outcome_ != Outcome::kPending || !std::isfinite(t) || !acc_b.allFinite()) return;
  // Samples come in time order: the map is touched once per second, the running bin the rest of the time.
  const long long second = Second(t);
  if (second != imu_second_ || imu_bin_ == nullptr) {
    imu_bin_ = &imu_[second];
    imu_second_ = second;
    while (imu_.size() > static_cast<size_t>(kKeep) && imu_.begin()->first != second) imu_.erase(imu_.begin());
  }
  imu_bin_->sum += acc_b.x();
  ++imu_bin_->n;
}

void ClockOffsetCheck::AddFix(double t, const Vec3& p_w, double sigma_h) {
  if (outcome_ != Outcome::kPending || !std::isfinite(t) || !p_w.allFinite()) return;
  if (have_fix_ && t > fix_t_ && t - fix_t_ <= 2.0) {
    const double dt = t - fix_t_, speed = (p_w - fix_p_).head<2>().norm() / dt, mid = 0.5 * (t + fix_t_);
    // Speeds of metre-level fixes are noise at walking pace: only those well above their σ count.
    if (have_speed_ && mid > speed_t_ && mid - speed_t_ <= 2.0 && (p_w - fix_p_).head<2>().norm() > 10.0 * sigma_h) {
      const double acc = (speed - speed_) / (mid - speed_t_);
      if (std::abs(acc) <= kMaxAcc) {
        Bin& b = gnss_[Second(0.5 * (mid + speed_t_))];
        b.sum += acc;
        ++b.n;
        while (gnss_.size() > static_cast<size_t>(kKeep)) gnss_.erase(gnss_.begin());
      }
    }
    have_speed_ = true;
    speed_ = speed;
    speed_t_ = mid;
  } else {
    have_speed_ = false;
  }
  have_fix_ = true;
  fix_t_ = t;
  fix_p_ = p_w;
  if (Second(t) >= next_decision_) {
    next_decision_ = Second(t) + 10;
    Decide();
  }
}

double ClockOffsetCheck::Correlation(int lag) const { return CorrelationAndCount(lag).first; }

std::pair<double, size_t> ClockOffsetCheck::CorrelationAndCount(int lag) const {
  // Pairs (IMU second k, GNSS second k + lag): a GNSS stamped `lag` s late shows the IMU's second k at k + lag.
  // Both maps are in key order: one walk, no allocation (Decide runs it for 121 lags every 10 s).
  double sa = 0.0, sg = 0.0, saa = 0.0, sgg = 0.0, sag = 0.0;
  size_t n = 0;
  auto it = gnss_.begin();
  for (const auto& [k, bin] : imu_) {
    while (it != gnss_.end() && it->first < k + lag) ++it;
    if (it == gnss_.end()) break;
    if (it->first != k + lag || bin.n == 0 || it->second.n == 0) continue;
    const double a = bin.sum / bin.n, g = it->second.sum / it->second.n;
    sa += a, sg += g, saa += a * a, sgg += g * g, sag += a * g;
    ++n;
  }
  if (n < static_cast<size_t>(kMinSeconds)) return {0.0, n};
  const double cn = static_cast<double>(n);
  const double vaa = saa - sa * sa / cn, vgg = sgg - sg * sg / cn, vag = sag - sa * sg / cn;
  if (vgg <= 0.0 || std::sqrt(vgg / cn) < kMinAccStd || vaa <= 0.0) return {0.0, n};  // not enough driving to say
  return {vag / std::sqrt(vaa * vgg), n};
}

void ClockOffsetCheck::Decide() {
  int best = 0;
  const double r0 = Correlation(0);
  double best_r = r0;
  size_t n = 0;
  for (int lag = -kMaxLag; lag <= kMaxLag; ++lag) {
    const auto [r, count] = CorrelationAndCount(lag);
    if (r > best_r) best = lag, best_r = r, n = count;
  }
  if (best_r < kMinCorrelation) return;
  if (best == 0) {
    outcome_ = Outcome::kOk;
    return;
  }
  // The correlation's own standard error, (1 − r²)/√n: lag 0 must be kSigmas of it below the best, and
  // 0.05 at least (a latency of half a second or so correlates at lags 0 and 1 alike: the offset state's).
  const double margin = kSigmas * (1.0 - best_r * best_r) / std::sqrt(static_cast<double>(n));
  if (best_r - r0 < std::max(0.05, margin)) return;
  outcome_ = Outcome::kRefuse;
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "the GNSS records are stamped %d s %s the IMU's (the track's accelerations match the IMU's %d s %s, "
                "correlation %.2f against %.2f at 0): a whole-second clock mix-up%s; state gnss.time_offset_s: %d",
                std::abs(best), best > 0 ? "after" : "before", std::abs(best), best > 0 ? "later" : "earlier", best_r,
                r0, std::abs(best) == 18 ? " (18 s: GPS time against UTC, the leap seconds)" : "", best);
  message_ = buf;
}

}  // namespace gins
