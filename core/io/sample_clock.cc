#include "core/io/sample_clock.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace gins {

double SampleClock::Stamp(double t) {
  if (!raw_.empty() && (t - raw_.back() > max_gap_ || t < raw_.back() - max_gap_)) Reset();
  raw_.push_back(t);
  if (raw_.size() > static_cast<size_t>(kWindow)) raw_.pop_front();
  const int n = static_cast<int>(raw_.size());
  double out = t;
  // The judgement every kJudgeEvery records (a median per record would cost a tenth of the ESKF's time).
  if (n >= kMinSamples && ++since_judged_ >= kJudgeEvery) {
    since_judged_ = 0;
    const double period = (raw_.back() - raw_.front()) / (n - 1);
    d2_.clear();
    for (int i = 1; i + 1 < n; ++i) d2_.push_back(std::abs(raw_[i + 1] - 2.0 * raw_[i] + raw_[i - 1]));
    std::nth_element(d2_.begin(), d2_.begin() + d2_.size() / 2, d2_.end());
    const double jitter = d2_[d2_.size() / 2];
    if (period > 0.0 && jitter > 0.1 * period) active_ = true;
    if (!(period > 0.0) || jitter < 0.05 * period) active_ = false;
  }
  if (n >= kMinSamples) {
    if (active_) {
      // The line through (i, raw_i), at the newest index; indices and stamps centred on the window's mean.
      const double i_mean = 0.5 * (n - 1);
      double t_mean = 0.0;
      for (double r : raw_) t_mean += r - raw_.front();
      t_mean /= n;
      double sxy = 0.0, sxx = 0.0;
      for (int i = 0; i < n; ++i) {
        sxy += (i - i_mean) * (raw_[i] - raw_.front() - t_mean);
        sxx += (i - i_mean) * (i - i_mean);
      }
      const double slope = sxy / sxx;
      double line = raw_.front() + t_mean + slope * (n - 1 - i_mean);
      if (have_out_ && line <= last_out_) line = last_out_ + 0.5 * slope;
      if (slope > 0.0 && std::abs(line - t) <= kMaxCorrection) {
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
