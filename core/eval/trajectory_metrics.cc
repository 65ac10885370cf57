#include "core/eval/trajectory_metrics.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/so3.h"

namespace gins {

std::vector<TimeWindow> MergeWindows(std::vector<TimeWindow> windows) {
  std::sort(windows.begin(), windows.end(),
            [](const TimeWindow& a, const TimeWindow& b) { return a.begin < b.begin; });
  std::vector<TimeWindow> out;
  for (const TimeWindow& w : windows) {
    if (!out.empty() && w.begin <= out.back().end) {
      TimeWindow& last = out.back();
      last.end = std::max(last.end, w.end);
      if (!w.source.empty() && last.source.find(w.source) == std::string::npos) {
        last.source += last.source.empty() ? w.source : "+" + w.source;
      }
    } else {
      out.push_back(w);
    }
  }
  return out;
}

Alignment ParseAlignment(const std::string& name) {
  if (name == "none") return Alignment::kNone;
  if (name == "yaw") return Alignment::kYaw;
  if (name == "se3") return Alignment::kSe3;
  throw std::invalid_argument("alignment must be none, yaw or se3, got '" + name + "'");
}

std::string AlignmentName(Alignment a) {
  switch (a) {
    case Alignment::kNone:
      return "none";
    case Alignment::kYaw:
      return "yaw";
    case Alignment::kSe3:
      return "se3";
  }
  return "none";
}

SampleSource VectorSource(const std::vector<TrajectorySample>& samples) {
  return [&samples, i = size_t{0}](TrajectorySample* s) mutable {
    if (i == samples.size()) return false;
    *s = samples[i++];
    return true;
  };
}

namespace {

// Histogram bins: 1024 per octave over [2^kMinExponent, 2^kMaxExponent) s; frexp's mantissa in [0.5, 1).
constexpr int kBinsPerOctave = 1024;
constexpr int kMinExponent = -40, kMaxExponent = 40;

size_t IntervalBin(double dt) {
  if (!(dt > 0.0)) return 0;
  int e = 0;
  const double m = std::frexp(dt, &e);
  if (e <= kMinExponent) return 0;
  if (e > kMaxExponent) return static_cast<size_t>((kMaxExponent - kMinExponent) * kBinsPerOctave - 1);
  const int k = std::min(kBinsPerOctave - 1, static_cast<int>((m - 0.5) * 2.0 * kBinsPerOctave));
  return static_cast<size_t>((e - 1 - kMinExponent) * kBinsPerOctave + k);
}

// The middle of a bin.
double IntervalBinCentre(size_t bin) {
  const int e = static_cast<int>(bin / kBinsPerOctave) + 1 + kMinExponent;
  const double k = static_cast<double>(bin % kBinsPerOctave);
  return std::ldexp(0.5 + (k + 0.5) / (2.0 * kBinsPerOctave), e);
}

}  // namespace

void IntervalMedian::Add(double t) {
  if (have_last_) {
    const double dt = t - last_t_;
    ++count_;
    if (histogram_.empty()) {
      ++exact_[dt];
      if (exact_.size() > kExactValues) {
        for (const auto& [value, n] : exact_) AddToHistogram(value, n);
        exact_.clear();
      }
    } else {
      AddToHistogram(dt, 1);
    }
  }
  have_last_ = true;
  last_t_ = t;
}

void IntervalMedian::AddToHistogram(double dt, uint64_t count) {
  if (histogram_.empty()) histogram_.assign(static_cast<size_t>((kMaxExponent - kMinExponent) * kBinsPerOctave), 0);
  histogram_[IntervalBin(dt)] += count;
}

std::optional<double> IntervalMedian::Median() const {
  if (count_ == 0) return std::nullopt;
  const uint64_t mid = count_ / 2;  // 0-based position in sorted order
  uint64_t below = 0;
  if (histogram_.empty()) {
    for (const auto& [value, n] : exact_) {
      below += n;
      if (below > mid) return value;
    }
  } else {
    for (size_t bin = 0; bin < histogram_.size(); ++bin) {
      below += histogram_[bin];
      if (below > mid) return IntervalBinCentre(bin);
    }
  }
  return std::nullopt;  // not reached: the counts add up to count_
}

double EffectiveMaxGap(const IntervalMedian& estimate_intervals, double max_gap) {
  const std::optional<double> median = estimate_intervals.Median();
  return median ? std::max(max_gap, kMedianGapFactor * *median) : max_gap;
}

double EffectiveMaxGap(SampleSource estimate, double max_gap) {
  IntervalMedian intervals;
  TrajectorySample s;
  while (estimate(&s)) intervals.Add(s.t);
  return EffectiveMaxGap(intervals, max_gap);
}

double EffectiveMaxGap(const std::vector<TrajectorySample>& estimate, double max_gap) {
  return EffectiveMaxGap(VectorSource(estimate), max_gap);
}

EstimateMatcher::EstimateMatcher(SampleSource estimate, double max_gap)
    : estimate_(std::move(estimate)), max_gap_(max_gap) {
  has_b_ = estimate_(&b_);
}

EstimateMatcher::Result EstimateMatcher::At(double t, TrajectorySample* est) {
  while (has_b_ && b_.t <= t) {
    a_ = b_;
    has_a_ = true;
    has_b_ = estimate_(&b_);
  }
  if (!has_a_) return Result::kOutsideSpan;  // before the estimate's first sample
  if (a_.t == t) {
    *est = a_;  // an estimate at the reference time itself
    return Result::kMatched;
  }
  if (!has_b_) return Result::kOutsideSpan;  // after its last
  const double span = b_.t - a_.t;
  if (span > max_gap_) return Result::kInGap;
  const double f = (t - a_.t) / span;
  est->t = t;
  est->p_w = (1.0 - f) * a_.p_w + f * b_.p_w;
  est->v_w = (1.0 - f) * a_.v_w + f * b_.v_w;
  est->q_wb = a_.q_wb.slerp(f, b_.q_wb);
  est->yaw_known = a_.yaw_known && b_.yaw_known;
  return Result::kMatched;
}

std::vector<MatchedPair> MatchAtReferenceTimes(const std::vector<TrajectorySample>& reference,
                                               const std::vector<TrajectorySample>& estimate, double max_gap) {
  std::vector<MatchedPair> pairs;
  EstimateMatcher matcher(VectorSource(estimate), max_gap);
  for (size_t i = 0; i < reference.size(); ++i) {
    MatchedPair m;
    if (matcher.At(reference[i].t, &m.est) != EstimateMatcher::Result::kMatched) continue;
    m.ref_index = i;
    m.ref = reference[i];
    pairs.push_back(m);
  }
  return pairs;
}

RigidTransform FitAlignment(const std::vector<MatchedPair>& pairs, Alignment alignment) {
  RigidTransform T;
  if (alignment == Alignment::kNone || pairs.empty()) return T;
  Vec3 mean_est = Vec3::Zero(), mean_ref = Vec3::Zero();
  for (const MatchedPair& m : pairs) {
    mean_est += m.est.p_w;
    mean_ref += m.ref.p_w;
  }
  mean_est /= static_cast<double>(pairs.size());
  mean_ref /= static_cast<double>(pairs.size());
  if (alignment == Alignment::kYaw) {
    // Minimises Σ|Rz(θ) e + t − r|²: with centred points, tan θ = Σ(e × r)_z / Σ(e·r) over E and N.
    double s = 0.0, c = 0.0;
    for (const MatchedPair& m : pairs) {
      const Vec3 e = m.est.p_w - mean_est, r = m.ref.p_w - mean_ref;
      s += e.x() * r.y() - e.y() * r.x();
      c += e.x() * r.x() + e.y() * r.y();
    }
    T.R = Eigen::AngleAxisd(std::atan2(s, c), Vec3::UnitZ()).toRotationMatrix();
  } else {
    Eigen::Matrix3Xd src(3, pairs.size()), dst(3, pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i) {
      src.col(static_cast<Eigen::Index>(i)) = pairs[i].est.p_w;
      dst.col(static_cast<Eigen::Index>(i)) = pairs[i].ref.p_w;
    }
    const Eigen::Matrix4d M = Eigen::umeyama(src, dst, false);
    T.R = M.topLeftCorner<3, 3>();
  }
  T.t = mean_ref - T.R * mean_est;
  return T;
}

TrajectoryEvaluator::TrajectoryEvaluator(SampleSource estimate, bool with_velocity, double max_gap,
                                         const MetricOptions& options, const RigidTransform& align)
    : matcher_(std::move(estimate), max_gap), with_velocity_(with_velocity), max_gap_(max_gap), options_(options),
      align_(options.alignment == Alignment::kNone ? RigidTransform() : align), q_align_(align_.R) {
  for (const TimeWindow& w : options_.outages) {
    OutageDrift o;
    o.window = w;
    outages_.push_back(o);
    by_begin_.push_back(by_begin_.size());
  }
  std::stable_sort(by_begin_.begin(), by_begin_.end(), [&](size_t a, size_t b) {
    return options_.outages[a].begin < options_.outages[b].begin;
  });
}

void TrajectoryEvaluator::AddReference(const TrajectorySample& ref) {
  if (have_ref_) travelled_ += (ref.p_w - last_ref_p_w_).norm();
  have_ref_ = true;
  last_ref_p_w_ = ref.p_w;
  TrajectorySample est;
  const EstimateMatcher::Result result = matcher_.At(ref.t, &est);
  reference_in_span_ += result != EstimateMatcher::Result::kOutsideSpan;
  if (result != EstimateMatcher::Result::kMatched) {
    open_segments_.clear();  // no segment may span an unevaluated reference sample
    return;
  }
  if (options_.alignment != Alignment::kNone) {
    est.p_w = align_.R * est.p_w + align_.t;
    est.q_wb = (q_align_ * est.q_wb).normalized();
    est.v_w = align_.R * est.v_w;
  }
  AddPair(ref, est);
}

void TrajectoryEvaluator::AddPair(const TrajectorySample& ref, const TrajectorySample& est) {
  // Absolute errors.
  const Vec3 d = est.p_w - ref.p_w;
  se_ += d.x() * d.x();
  sn_ += d.y() * d.y();
  su_ += d.z() * d.z();
  const double err_h = d.head<2>().norm();
  sum_h_ += err_h;
  if (err_h > max_h_) {
    max_h_ = err_h;
    t_max_h_ = ref.t;
  }
  svel_ += (est.v_w - ref.v_w).squaredNorm();
  if (ref.yaw_known && est.yaw_known) {
    satt_ += LogQuat<double>(ref.q_wb.conjugate() * est.q_wb).squaredNorm();
    const double dyaw =
        WrapAngle(YawOfXAxis<double>(est.q_wb.toRotationMatrix()) - YawOfXAxis<double>(ref.q_wb.toRotationMatrix()));
    syaw_ += dyaw * dyaw;
    max_heading_deg_ = std::max(max_heading_deg_, std::abs(dyaw) * kRadToDeg);
    ++attitude_samples_;
  }
  ++samples_;

  // Relative error: this pair ends the segments of the open starts it is segment_length or more beyond (the
  // oldest first: the first pair that far along the path ends each), then starts one.
  if (options_.segment_length > 0.0) {
    while (!open_segments_.empty() && !(travelled_ - open_segments_.front().travelled < options_.segment_length)) {
      const SegmentStart& i = open_segments_.front();
      const double dist = travelled_ - i.travelled;
      const Vec3 d_est = est.p_w - i.p_est_w;
      const Vec3 d_ref = ref.p_w - i.p_ref_w;
      const double pct = 100.0 * (d_est - d_ref).norm() / dist;
      rel_sum_ += pct;
      rel_sq_ += pct * pct;
      rel_max_ = std::max(rel_max_, pct);
      ++segments_;
      open_segments_.pop_front();
    }
    open_segments_.push_back({travelled_, est.p_w, ref.p_w});
  }

  // Drift over outages: the windows holding this time; and the error outside them and their settle times.
  while (next_window_ < by_begin_.size() && options_.outages[by_begin_[next_window_]].begin <= ref.t) {
    open_windows_.push_back(by_begin_[next_window_++]);
  }
  const double settle = options_.outage_settle;
  bool outside = true;
  for (size_t w : open_windows_) {
    if (ref.t > options_.outages[w].end + settle) continue;
    outside = false;
    if (ref.t > options_.outages[w].end) continue;
    OutageDrift& o = outages_[w];
    if (o.samples == 0 || err_h > o.max_h) {
      o.max_h = err_h;
      o.t_max = ref.t;
    }
    o.final_h = err_h;
    ++o.samples;
  }
  open_windows_.erase(std::remove_if(open_windows_.begin(), open_windows_.end(),
                                     [&](size_t w) { return ref.t > options_.outages[w].end + settle; }),
                      open_windows_.end());
  if (outside) {
    s_outside_h_ += err_h * err_h;
    ++outside_;
  }
}

TrajectoryMetrics TrajectoryEvaluator::Metrics() const {
  if (samples_ == 0) throw std::invalid_argument("no reference time falls inside the estimate's time span");
  TrajectoryMetrics m;
  m.max_gap = max_gap_;
  m.alignment = options_.alignment;
  m.align = align_;
  m.reference_in_span = reference_in_span_;
  m.samples = samples_;
  const double n = static_cast<double>(samples_);
  m.rmse_e = std::sqrt(se_ / n);
  m.rmse_n = std::sqrt(sn_ / n);
  m.rmse_v = std::sqrt(su_ / n);
  m.rmse_h = std::sqrt((se_ + sn_) / n);
  m.rmse_3d = std::sqrt((se_ + sn_ + su_) / n);
  m.mean_h = sum_h_ / n;
  m.max_h = max_h_;
  m.t_max_h = t_max_h_;
  if (with_velocity_) m.rmse_vel = std::sqrt(svel_ / n);
  m.attitude_samples = attitude_samples_;
  const double n_att = static_cast<double>(std::max<uint64_t>(attitude_samples_, 1));
  m.rmse_att_deg = std::sqrt(satt_ / n_att) * kRadToDeg;
  m.rmse_heading_deg = std::sqrt(syaw_ / n_att) * kRadToDeg;
  m.max_heading_deg = max_heading_deg_;

  m.segment_length = options_.segment_length;
  m.segments = segments_;
  m.rel_max_pct = rel_max_;
  if (segments_ > 0) {
    m.rel_mean_pct = rel_sum_ / static_cast<double>(segments_);
    m.rel_rms_pct = std::sqrt(rel_sq_ / static_cast<double>(segments_));
  }

  m.outages = outages_;
  double outage_sq = 0.0;
  for (const OutageDrift& o : outages_) {
    if (o.samples == 0) continue;
    ++m.outages_scored;
    outage_sq += o.max_h * o.max_h;
    m.outage_max = std::max(m.outage_max, o.max_h);
  }
  if (m.outages_scored > 0) m.outage_rms = std::sqrt(outage_sq / static_cast<double>(m.outages_scored));
  m.outage_settle = options_.outage_settle;
  if (!outages_.empty()) {
    m.outside_samples = outside_;
    if (outside_ > 0) m.rmse_h_outside = std::sqrt(s_outside_h_ / static_cast<double>(outside_));
  }
  return m;
}

TrajectoryMetrics EvaluateTrajectory(const std::vector<TrajectorySample>& reference, bool reference_has_velocity,
                                     const std::vector<TrajectorySample>& estimate, bool estimate_has_velocity,
                                     const MetricOptions& options) {
  const double max_gap = EffectiveMaxGap(estimate, options.max_gap);
  RigidTransform align;
  if (options.alignment != Alignment::kNone) {
    align = FitAlignment(MatchAtReferenceTimes(reference, estimate, max_gap), options.alignment);
  }
  TrajectoryEvaluator evaluator(VectorSource(estimate), reference_has_velocity && estimate_has_velocity, max_gap,
                                options, align);
  for (const TrajectorySample& r : reference) evaluator.AddReference(r);
  return evaluator.Metrics();
}

}  // namespace gins
