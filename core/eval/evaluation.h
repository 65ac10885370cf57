// Accuracy against a truth file (DESIGN §5), computed as the estimate streams in: the estimate is
// interpolated at each truth time it brackets, and the truth is read as the estimate advances, so memory
// holds neither.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/io/truth_reader.h"
#include "core/nav_state.h"

namespace gins {

struct AccuracyMetrics {
  uint64_t count = 0;
  double rmse_3d = 0.0, rmse_h = 0.0, rmse_v = 0.0, max_h = 0.0;
  double rmse_vel = 0.0;          // m/s, 3-D
  double rmse_heading_deg = 0.0;  // yaw of the body x axis
  double rmse_att_deg = 0.0;      // full attitude error angle
};

class StreamingEvaluator {
 public:
  // Pulls the truth from `truth` (the next sample in increasing time, false at the end) as the estimates
  // advance, so memory holds one truth sample, e.g. from its own TruthReader.
  explicit StreamingEvaluator(std::function<bool(TruthSample*)> truth);
  // Over truth samples held in memory.
  explicit StreamingEvaluator(std::vector<TruthSample> truth);
  // Estimates must arrive in non-decreasing time.
  void Add(const NavState& x);
  AccuracyMetrics Metrics() const;

 private:
  void Accumulate(const TruthSample& truth, const NavState& est);
  void NextTruth() { have_next_ = truth_(&next_); }
  std::function<bool(TruthSample*)> truth_;
  TruthSample next_;  // the first truth sample not yet passed
  bool have_next_ = false;
  bool have_prev_ = false;
  NavState prev_;
  uint64_t n_ = 0;
  double sum_h2_ = 0.0, sum_v2_ = 0.0, max_h_ = 0.0, sum_vel2_ = 0.0, sum_yaw2_ = 0.0, sum_att2_ = 0.0;
};

}  // namespace gins
