#include "core/eval/gnss_outages.h"

#include <algorithm>
#include <cmath>

namespace gins {

GnssOutageSchedule::GnssOutageSchedule(std::vector<std::pair<double, double>> windows, double periodic_first_start,
                                       double periodic_duration, double periodic_period)
    : windows_(std::move(windows)),
      periodic_first_start_(periodic_first_start),
      periodic_duration_(periodic_period > 0.0 ? periodic_duration : 0.0),
      periodic_period_(periodic_period) {}

bool GnssOutageSchedule::Contains(double t, double first_time) const {
  const double rel = t - first_time;
  for (const auto& [start, duration] : windows_) {
    if (rel >= start && rel < start + duration) return true;
  }
  if (periodic_duration_ > 0.0 && rel >= periodic_first_start_) {
    const double phase = std::fmod(rel - periodic_first_start_, periodic_period_);
    if (phase < periodic_duration_) return true;
  }
  return false;
}

std::vector<std::pair<double, double>> GnssOutageSchedule::Windows(double first_time, double last_time) const {
  std::vector<std::pair<double, double>> w;
  for (const auto& [start, duration] : windows_) {
    if (first_time + start <= last_time) w.emplace_back(first_time + start, first_time + start + duration);
  }
  if (periodic_duration_ > 0.0) {
    for (int k = 0;; ++k) {
      const double begin = first_time + periodic_first_start_ + k * periodic_period_;
      if (begin > last_time) break;
      w.emplace_back(begin, begin + periodic_duration_);
    }
  }
  std::sort(w.begin(), w.end());
  std::vector<std::pair<double, double>> merged;
  for (const auto& x : w) {
    if (!merged.empty() && x.first <= merged.back().second) {
      merged.back().second = std::max(merged.back().second, x.second);
    } else {
      merged.push_back(x);
    }
  }
  return merged;
}

void GnssGapTracker::Add(double t) {
  if (have_last_ && t - last_ > min_gap_) gaps_.emplace_back(last_, t);
  if (!have_last_ || t > last_) last_ = t;
  have_last_ = true;
}

}  // namespace gins
