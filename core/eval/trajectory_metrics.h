// Accuracy of a trajectory against a reference (a truth, or another estimate), the way the GNSS/INS
// literature reports it: absolute errors in the geo-referenced frame (no alignment unless asked for),
// relative error over travelled distance, and drift over GNSS outages.
//
// Definitions (both trajectories in one ENU frame):
// - Pairs: the estimate is interpolated at each reference time it brackets (position and velocity
//   linearly, attitude by slerp) when its two samples are at most max(max_gap, 3 × the estimate's median
//   sample interval (IntervalMedian)) apart (1 s for IMU-rate outputs; a keyframe-rate output at ~1 Hz gets
//   3 s, so its slightly longer intervals in GNSS outages still count); reference times in larger estimate
//   gaps, or outside the estimate's span, are not evaluated.
// - Position errors e = p_est − p_ref: 3-D, horizontal |e_EN| and vertical e_U RMSE; largest horizontal.
// - Velocity RMSE |v_est − v_ref| when both carry velocities.
// - Attitude RMSE: RMS of |Log(R_refᵀ R_est)|; heading: RMS of the wrapped difference of the yaws of the body
//   x axes (ENU, about up). Both over the pairs where both have a yaw: an estimate whose yaw σ says it has
//   none (a state CSV's sigma_att_u of kUnknownYawSigma: at rest before the initialisation) is left out.
// - Relative error over travelled distance L (default 100 m): from every pair i, the first pair j at
//   which the reference has travelled (3-D path length) at least L, with no unevaluated reference sample
//   between them; error = |(p_est,j − p_est,i) − (p_ref,j − p_ref,i)| / d_ij · 100 %, d_ij the reference's
//   path length from i to j. Reported as mean, RMS and max over all such segments.
// - Outage drift: for each window [begin, end], the largest horizontal error of the pairs inside it (not
//   reduced by the error at its start: with RTK that is centimetres); RMS and max over the windows that
//   have pairs.
// - Horizontal RMSE outside outages: over the pairs in no window [begin, end + outage_settle] (the settle
//   time leaves out the re-convergence after each outage), so the accuracy with GNSS is not hidden by the
//   drift without it. Only when there are windows.
// - Alignment (off by default; for inputs that are not geo-referenced): the rigid transform of the
//   estimate minimising Σ|R p_est + t − p_ref|² over the pairs: yaw + translation (4-DoF) or full SE(3)
//   (Umeyama, no scale). It is applied to positions, attitudes and velocities before every metric.
//
// Without alignment everything is computed in one pass over the reference and the estimate, both streamed
// (TrajectoryEvaluator), after a first pass over the estimate for its median interval: memory does not grow
// with the log, so `gins run` can score hours of IMU-rate outputs. This is the only evaluator: `gins eval`,
// and `gins run`'s "accuracy" and "comparison" (core/eval/run_comparison.h, from the committed outputs).
#pragma once

#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/io/trajectory_reader.h"

namespace gins {

struct TimeWindow {
  double begin = 0.0;
  double end = 0.0;
  std::string source;  // e.g. "config", "log gap"; merged windows join theirs with '+'
};

// Sorted by begin, overlapping or touching windows merged into one.
std::vector<TimeWindow> MergeWindows(std::vector<TimeWindow> windows);

// Pulls the next sample (strictly increasing time) into *sample; false at the end. E.g. a TrajectoryReader.
using SampleSource = std::function<bool(TrajectorySample* sample)>;
// The samples of a vector in order (not copied: the vector must outlive the source).
SampleSource VectorSource(const std::vector<TrajectorySample>& samples);

// The median of the intervals between consecutive times (the interval at position n/2 of the sorted n,
// as std::nth_element finds it), in bounded memory whatever the number of times: exact while the intervals
// take at most kExactValues distinct values (our outputs' times are printed to 1 µs: an IMU-rate output has
// a handful, a keyframe-rate one tens), else from a histogram on bins 2^-10 wide in relative terms (1024
// per octave, intervals from 2^-40 s to 2^40 s), within 0.05 % — plenty for a gap threshold.
class IntervalMedian {
 public:
  static constexpr size_t kExactValues = 1024;
  // Times must increase.
  void Add(double t);
  // None with fewer than two times.
  std::optional<double> Median() const;

 private:
  void AddToHistogram(double dt, uint64_t count);
  bool have_last_ = false;
  double last_t_ = 0.0;
  uint64_t count_ = 0;
  std::map<double, uint64_t> exact_;  // interval -> count, until there are too many distinct ones
  std::vector<uint64_t> histogram_;   // then counts per bin (allocated when needed)
};

// The gap interpolated across is at least this many times the estimate's median sample interval.
constexpr double kMedianGapFactor = 3.0;
// max(max_gap, kMedianGapFactor × median interval of the estimate): the one gap rule of every evaluation
// (`gins eval`, and `gins run`'s accuracy and comparison). The source and vector forms are a first pass over
// the estimate.
double EffectiveMaxGap(const IntervalMedian& estimate_intervals, double max_gap);
double EffectiveMaxGap(SampleSource estimate, double max_gap);
double EffectiveMaxGap(const std::vector<TrajectorySample>& estimate, double max_gap);

enum class Alignment { kNone, kYaw, kSe3 };
// "none" | "yaw" | "se3"; throws std::invalid_argument for anything else.
Alignment ParseAlignment(const std::string& name);
std::string AlignmentName(Alignment a);

struct RigidTransform {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
};

struct MetricOptions {
  double max_gap = 1.0;           // s, at least; see kMedianGapFactor

  double segment_length = 100.0;  // m
  Alignment alignment = Alignment::kNone;
  std::vector<TimeWindow> outages;  // absolute times
  double outage_settle = 5.0;       // s after each outage's end still left out of the RMSE outside outages
};

// One evaluated reference time.
struct MatchedPair {
  size_t ref_index = 0;  // into the reference
  TrajectorySample ref, est;
};

// The estimate at reference times that do not decrease, merged from its stream by the pair rules above:
// holds the two estimate samples around the current reference time, so memory does not grow with either.
class EstimateMatcher {
 public:
  enum class Result { kOutsideSpan, kInGap, kMatched };
  // Reads the estimate's first sample.
  EstimateMatcher(SampleSource estimate, double max_gap);
  // *est is set when kMatched: the estimate at `t` (its own sample there, or interpolated).
  Result At(double t, TrajectorySample* est);

 private:
  SampleSource estimate_;
  double max_gap_;
  TrajectorySample a_, b_;  // the latest sample at or before the reference time, and the one after it
  bool has_a_ = false, has_b_ = false;
};

std::vector<MatchedPair> MatchAtReferenceTimes(const std::vector<TrajectorySample>& reference,
                                               const std::vector<TrajectorySample>& estimate, double max_gap);

// The transform taking the estimate's positions onto the reference's (least squares over the pairs).
RigidTransform FitAlignment(const std::vector<MatchedPair>& pairs, Alignment alignment);

struct OutageDrift {
  TimeWindow window;
  uint64_t samples = 0;
  double max_h = 0.0;    // m, largest horizontal error inside the window
  double t_max = 0.0;    // time of that error
  double final_h = 0.0;  // m, horizontal error at the window's last pair
};

struct TrajectoryMetrics {
  double max_gap = 0.0;            // s, the gap interpolated across (EffectiveMaxGap)
  uint64_t samples = 0;            // pairs evaluated
  uint64_t reference_in_span = 0;  // reference samples inside the estimate's time span
  double rmse_3d = 0.0, rmse_h = 0.0, rmse_v = 0.0, rmse_e = 0.0, rmse_n = 0.0;
  double mean_h = 0.0, max_h = 0.0, t_max_h = 0.0;
  std::optional<double> rmse_vel;  // m/s; when both have velocities
  // Over the pairs where both have a yaw (attitude_samples; TrajectorySample::yaw_known).
  double rmse_att_deg = 0.0, rmse_heading_deg = 0.0, max_heading_deg = 0.0;
  uint64_t attitude_samples = 0;
  // Relative error over travelled distance.
  double segment_length = 0.0;
  uint64_t segments = 0;
  double rel_mean_pct = 0.0, rel_rms_pct = 0.0, rel_max_pct = 0.0;
  // Drift over outages (every window of MetricOptions::outages, in order, scored or not).
  std::vector<OutageDrift> outages;
  uint64_t outages_scored = 0;
  double outage_rms = 0.0, outage_max = 0.0;
  // Horizontal RMSE over the pairs outside every window and its settle time; set when there are windows
  // and such pairs.
  double outage_settle = 0.0;
  uint64_t outside_samples = 0;
  std::optional<double> rmse_h_outside;
  Alignment alignment = Alignment::kNone;
  RigidTransform align;  // applied to the estimate (identity without alignment)
};

// Every metric of one estimate, accumulated as the reference streams by in time order; the estimate is
// merged in from its own stream (EstimateMatcher). Memory does not grow with the trajectories' length: the
// sums are running sums, and the relative error keeps a deque of the pairs of the last `segment_length`
// metres of reference travel (the segment starts still waiting for their end), emptied at every
// unevaluated reference sample; it is bounded by distance and by the length of a standstill, not by the log.
// The numbers are those of the definitions above in the same order of summation (EvaluateTrajectory is
// this over vectors).
class TrajectoryEvaluator {
 public:
  // `max_gap`: EffectiveMaxGap of the estimate (a first pass over it). `with_velocity`: both the reference and
  // the estimate carry velocities. With options.alignment other than none, `align` (FitAlignment over the
  // pairs, also a first pass) is applied to each estimate before every metric.
  TrajectoryEvaluator(SampleSource estimate, bool with_velocity, double max_gap, const MetricOptions& options,
                      const RigidTransform& align = RigidTransform());
  void AddReference(const TrajectorySample& ref);
  // Throws std::invalid_argument when nothing was evaluated (no reference time inside the estimate).
  TrajectoryMetrics Metrics() const;

 private:
  void AddPair(const TrajectorySample& ref, const TrajectorySample& est);

  EstimateMatcher matcher_;
  bool with_velocity_;
  double max_gap_;
  MetricOptions options_;
  RigidTransform align_;
  Quat q_align_;
  uint64_t samples_ = 0, reference_in_span_ = 0, attitude_samples_ = 0;
  // Absolute errors: sums of squares over the pairs (E, N, U, velocity, attitude, heading).
  double se_ = 0.0, sn_ = 0.0, su_ = 0.0, sum_h_ = 0.0, svel_ = 0.0, satt_ = 0.0, syaw_ = 0.0;
  double max_h_ = 0.0, t_max_h_ = 0.0, max_heading_deg_ = 0.0;
  // Relative error: the reference's path length so far, and the pairs still waiting for the pair
  // segment_length further on (starts with no unevaluated reference sample since).
  bool have_ref_ = false;
  Vec3 last_ref_p_w_ = Vec3::Zero();
  double travelled_ = 0.0;
  struct SegmentStart {
    double travelled;
    Vec3 p_est_w, p_ref_w;
  };
  std::deque<SegmentStart> open_segments_;
  uint64_t segments_ = 0;
  double rel_sum_ = 0.0, rel_sq_ = 0.0, rel_max_ = 0.0;
  // Outage drift, per window of options_.outages; windows are opened in order of their begin and closed
  // once the reference passes their end plus the settle time.
  std::vector<OutageDrift> outages_;
  std::vector<size_t> by_begin_;  // window indices sorted by begin
  size_t next_window_ = 0;        // into by_begin_: the first window not yet opened
  std::vector<size_t> open_windows_;
  uint64_t outside_ = 0;
  double s_outside_h_ = 0.0;  // sum of squared horizontal errors outside windows and settle times
};

// The metrics over trajectories in memory: EffectiveMaxGap, FitAlignment over MatchAtReferenceTimes when
// aligning, then TrajectoryEvaluator. Throws std::invalid_argument when nothing can be evaluated (no
// reference time inside the estimate).
TrajectoryMetrics EvaluateTrajectory(const std::vector<TrajectorySample>& reference, bool reference_has_velocity,
                                     const std::vector<TrajectorySample>& estimate, bool estimate_has_velocity,
                                     const MetricOptions& options);

}  // namespace gins
