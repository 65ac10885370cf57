// Simulated GNSS outages (gnss.outages_s, gnss.periodic_outages_s): which fixes a run drops, and the
// absolute windows it reports. Times in the config are seconds after the log's first record; a window is
// [start, start + duration).
#pragma once

#include <utility>
#include <vector>

namespace gins {

class GnssOutageSchedule {
 public:
  GnssOutageSchedule() = default;
  // `windows`: [start, duration] pairs; a periodic pattern repeats [first_start + k·period, + duration)
  // for k = 0, 1, ... (none when duration <= 0).
  GnssOutageSchedule(std::vector<std::pair<double, double>> windows, double periodic_first_start,
                     double periodic_duration, double periodic_period);

  bool empty() const { return windows_.empty() && periodic_duration_ <= 0.0; }
  // True when time t lies in a window, with the log's first record at first_time.
  bool Contains(double t, double first_time) const;
  // The absolute windows [begin, end) that begin at or before last_time (so every dropped fix lies in one),
  // sorted by begin, overlaps merged.
  std::vector<std::pair<double, double>> Windows(double first_time, double last_time) const;

 private:
  std::vector<std::pair<double, double>> windows_;  // [start, duration], relative
  double periodic_first_start_ = 0.0, periodic_duration_ = 0.0, periodic_period_ = 0.0;
};

// Gaps in the log's own GNSS stream (a receiver outage, a tunnel): consecutive fixes further apart than
// `min_gap` seconds give a window (t_before, t_after).
class GnssGapTracker {
 public:
  explicit GnssGapTracker(double min_gap = 3.0) : min_gap_(min_gap) {}
  void Add(double t);
  const std::vector<std::pair<double, double>>& gaps() const { return gaps_; }

 private:
  double min_gap_;
  double last_ = 0.0;
  bool have_last_ = false;
  std::vector<std::pair<double, double>> gaps_;
};

}  // namespace gins
