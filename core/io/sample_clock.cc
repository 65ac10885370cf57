#include "core/io/sample_clock.h"

#include <algorithm>
#include <cmath>

namespace gins {

void SampleClock::Reset() {
  raw_.clear();
  d2_.clear();
  sum_d2_ = 0.0;
  active_ = false;
  since_fit_ = kFitEvery;
}

void SampleClock::Fit() {
  // The least-squares line through (i, raw_i), at the newest index; indices and stamps centred.
  const int n = static_cast<int>(raw_.size());
  const double i_mean = 0.5 * (n - 1);
  double t_mean = 0.0;
  for (double r : raw_) t_mean += r - raw_.front();
  t_mean /= n;
  double sxy = 0.0, sxx = 0.0;
  for (int i = 0; i < n; ++i) {
    sxy += (i - i_mean) * (raw_[i] - raw_.front() - t_mean);
    sxx += (i - i_mean) * (i - i_mean);
  }
  slope_ = sxy / sxx;
  fit_end_ = raw_.front() + t_mean + slope_ * (n - 1 - i_mean);
  since_fit_ = 0;
}

double SampleClock::Stamp(double t) {
  if (!raw_.empty() && (t - raw_.back() > max_gap_ || t < raw_.back() - max_gap_)) Reset();
  raw_.push_back(t);
  const size_t n = raw_.size();
  if (n >= 3) {
    d2_.push_back(std::abs(raw_[n - 1] - 2.0 * raw_[n - 2] + raw_[n - 3]));
    sum_d2_ += d2_.back();
  }
  if (n > static_cast<size_t>(kWindow)) {
    raw_.pop_front();
    sum_d2_ -= d2_.front();
    d2_.pop_front();
  }
  double out = t;
  if (raw_.size() >= static_cast<size_t>(kMinSamples)) {
    const double period = (raw_.back() - raw_.front()) / static_cast<double>(raw_.size() - 1);
    const double jitter = std::max(sum_d2_, 0.0) / static_cast<double>(d2_.size());
    const bool was_active = active_;
    if (period > 0.0 && jitter > 0.1 * period) active_ = true;
    if (!(period > 0.0) || jitter < 0.05 * period) active_ = false;
    if (active_) {
      if (!was_active || ++since_fit_ >= kFitEvery) {
        Fit();
      } else {
        fit_end_ += slope_;  // the last fit's line, one index on
      }
      double line = fit_end_;
      if (have_out_ && line <= last_out_) line = last_out_ + 0.5 * slope_;
      if (slope_ > 0.0 && std::abs(line - t) <= kMaxCorrection) {
        out = line;
      } else {
        Reset();  // not the stream the window describes any more (a rate change, a restart)
      }
    }
  }
  if (out != t) {
    ++regularized_;
    max_correction_ = std::max(max_correction_, std::abs(out - t));
  }
  have_out_ = true;
  last_out_ = out;
  return out;
}

}  // namespace gins
