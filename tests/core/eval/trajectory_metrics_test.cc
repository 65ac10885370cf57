// Trajectory metrics (core/trajectory_metrics.h) on constructed trajectories with known answers: offsets,
// rotations, gaps, alignment recovering a known transform, relative error over distance, outage drift; the
// streaming evaluator against a whole-trajectory oracle; the median interval.
#include "core/eval/trajectory_metrics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/so3.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kT0 = 5000.0;

// A level drive: straight east at 10 m/s for `straight` s, then a left circle of radius 50 m; yaw follows the
// path. Sampled every dt from kT0.
std::vector<TrajectorySample> Drive(double duration, double dt, double straight = 1e9) {
  std::vector<TrajectorySample> out;
  const double v = 10.0, r = 50.0;
  for (int k = 0; k * dt <= duration + 1e-9; ++k) {
    const double s = k * dt;
    TrajectorySample x;
    x.t = kT0 + s;
    if (s <= straight) {
      x.p_w = Vec3(v * s, 0.0, 2.0);
      x.q_wb = Quat::Identity();
      x.v_w = Vec3(v, 0.0, 0.0);
    } else {
      const double a = v * (s - straight) / r;  // angle travelled on the circle
      x.p_w = Vec3(v * straight + r * std::sin(a), r * (1.0 - std::cos(a)), 2.0);
      x.q_wb = QuatFromYaw(a);
      x.v_w = Vec3(v * std::cos(a), v * std::sin(a), 0.0);
    }
    out.push_back(x);
  }
  return out;
}

MetricOptions NoOutages() { return MetricOptions(); }

TEST(TrajectoryMetrics, ExactEstimateHasZeroErrors) {
  const auto ref = Drive(60.0, 0.125, 20.0);
  const TrajectoryMetrics m = EvaluateTrajectory(ref, true, ref, true, NoOutages());
  EXPECT_EQ(m.samples, ref.size());
  EXPECT_EQ(m.reference_in_span, ref.size());
  EXPECT_LT(m.rmse_3d, 1e-12);
  EXPECT_LT(*m.rmse_vel, 1e-12);
  EXPECT_LT(m.rmse_att_deg, 1e-6);
  EXPECT_LT(m.rmse_heading_deg, 1e-6);
  EXPECT_GT(m.segments, 0u);
  EXPECT_LT(m.rel_max_pct, 1e-9);
}

TEST(TrajectoryMetrics, ConstantOffsetsGiveKnownRmse) {
  const auto ref = Drive(60.0, 0.125, 20.0);
  auto est = ref;
  for (auto& x : est) {
    x.p_w += Vec3(3.0, -4.0, 1.0);
    x.v_w += Vec3(0.0, 0.3, -0.4);
  }
  const TrajectoryMetrics m = EvaluateTrajectory(ref, true, est, true, NoOutages());
  EXPECT_NEAR(m.rmse_h, 5.0, 1e-9);
  EXPECT_NEAR(m.rmse_e, 3.0, 1e-9);
  EXPECT_NEAR(m.rmse_n, 4.0, 1e-9);
  EXPECT_NEAR(m.rmse_v, 1.0, 1e-9);
  EXPECT_NEAR(m.rmse_3d, std::sqrt(26.0), 1e-9);
  EXPECT_NEAR(m.max_h, 5.0, 1e-9);
  EXPECT_NEAR(m.mean_h, 5.0, 1e-9);
  ASSERT_TRUE(m.rmse_vel.has_value());
  EXPECT_NEAR(*m.rmse_vel, 0.5, 1e-9);
  // A constant offset does not change displacements: no relative error.
  EXPECT_LT(m.rel_max_pct, 1e-9);
  // Without velocities on either side there is no velocity RMSE.
  EXPECT_FALSE(EvaluateTrajectory(ref, true, est, false, NoOutages()).rmse_vel.has_value());
  EXPECT_FALSE(EvaluateTrajectory(ref, false, est, true, NoOutages()).rmse_vel.has_value());
}

TEST(TrajectoryMetrics, RotationsGiveKnownAttitudeAndHeadingErrors) {
  const auto ref = Drive(60.0, 0.125, 20.0);
  // A yaw error of 2°: attitude and heading errors both 2°.
  auto yawed = ref;
  for (auto& x : yawed) x.q_wb = x.q_wb * QuatFromYaw(2.0 * kDegToRad);
  TrajectoryMetrics m = EvaluateTrajectory(ref, true, yawed, true, NoOutages());
  EXPECT_NEAR(m.rmse_heading_deg, 2.0, 1e-6);
  EXPECT_NEAR(m.max_heading_deg, 2.0, 1e-6);
  EXPECT_NEAR(m.rmse_att_deg, 2.0, 1e-6);
  // A roll error of 3° about the body x axis: 3° of attitude, no heading error (x stays put).
  auto rolled = ref;
  for (auto& x : rolled) x.q_wb = x.q_wb * Quat(Eigen::AngleAxisd(3.0 * kDegToRad, Vec3::UnitX()));
  m = EvaluateTrajectory(ref, true, rolled, true, NoOutages());
  EXPECT_NEAR(m.rmse_att_deg, 3.0, 1e-6);
  EXPECT_LT(m.rmse_heading_deg, 1e-6);
  // Heading errors wrap: truth at +179°, estimate at −179° is 2° off.
  std::vector<TrajectorySample> a(3), b(3);
  for (int k = 0; k < 3; ++k) {
    a[k].t = b[k].t = kT0 + k;
    a[k].q_wb = QuatFromYaw(179.0 * kDegToRad);
    b[k].q_wb = QuatFromYaw(-179.0 * kDegToRad);
  }
  EXPECT_NEAR(EvaluateTrajectory(a, false, b, false, NoOutages()).rmse_heading_deg, 2.0, 1e-6);
}

// An estimate without a yaw (at rest before the initialisation, its σ that of an unknown angle) counts for
// position, not for attitude or heading; nor does an interpolation touching such a sample.
TEST(TrajectoryMetrics, StatesWithoutAYawAreLeftOutOfAttitudeAndHeading) {
  const auto ref = Drive(10.0, 0.5);
  auto est = ref;
  for (size_t k = 0; k < est.size(); ++k) {
    est[k].p_w.x() += 0.1;
    if (k < 4) {
      est[k].q_wb = QuatFromYaw(1.0);  // an arbitrary yaw
      est[k].yaw_known = false;
    } else {
      est[k].q_wb = est[k].q_wb * QuatFromYaw(2.0 * kDegToRad);
    }
  }
  const TrajectoryMetrics m = EvaluateTrajectory(ref, true, est, true, NoOutages());
  EXPECT_EQ(m.samples, ref.size());
  EXPECT_EQ(m.attitude_samples, ref.size() - 4);
  EXPECT_NEAR(m.rmse_h, 0.1, 1e-9);
  EXPECT_NEAR(m.rmse_heading_deg, 2.0, 1e-6);
  EXPECT_NEAR(m.max_heading_deg, 2.0, 1e-6);
  // At reference times between the samples, those bracketed by an unknown yaw are left out too.
  auto mid = ref;
  for (auto& x : mid) x.t += 0.25;
  mid.pop_back();
  const TrajectoryMetrics i = EvaluateTrajectory(mid, true, est, true, NoOutages());
  EXPECT_EQ(i.attitude_samples, i.samples - 4);
  EXPECT_NEAR(i.rmse_heading_deg, 2.0, 1e-6);
}

TEST(TrajectoryMetrics, InterpolatesAtReferenceTimesAndSkipsGaps) {
  const auto ref = Drive(30.0, 0.125);  // straight: linear interpolation is exact
  // The estimate at 64 Hz, half a sample later than the reference's times, with a 2 s hole after 10 s.
  std::vector<TrajectorySample> est;
  for (const auto& x : Drive(30.0, 0.015625)) {
    const double s = x.t - kT0;
    if (s > 10.0 && s < 12.0) continue;
    TrajectorySample y = x;
    y.t += 0.0078125;
    y.p_w.x() += 0.078125;  // the same place, 0.0078125 s later at 10 m/s
    est.push_back(y);
  }
  const TrajectoryMetrics m = EvaluateTrajectory(ref, true, est, true, NoOutages());
  // Reference times 0.125 ... 30 (the estimate starts at 0.0078125): 240; 10.125 ... 12 fall in the hole
  // (10.0078125, 12.0078125): 16 of them.
  EXPECT_EQ(m.reference_in_span, 240u);
  EXPECT_EQ(m.samples, 240u - 16u);
  EXPECT_LT(m.rmse_3d, 1e-9);
  EXPECT_NEAR(m.max_gap, 1.0, 1e-12);  // 100 Hz: the 1 s floor
  // A keyframe-rate estimate (1.1 s apart, median 1 s) still counts: 3 × the median interval.
  std::vector<TrajectorySample> sparse;
  for (const auto& x : Drive(30.0, 1.0)) sparse.push_back(x);
  sparse.erase(sparse.begin() + 5);  // one 2 s interval, within 3 s
  const TrajectoryMetrics ms = EvaluateTrajectory(ref, true, sparse, true, NoOutages());
  EXPECT_NEAR(ms.max_gap, 3.0, 1e-12);
  EXPECT_EQ(ms.samples, 241u);
  EXPECT_LT(ms.rmse_3d, 1e-9);
}

TEST(TrajectoryMetrics, NothingToEvaluateThrows) {
  const auto ref = Drive(10.0, 0.125);
  auto later = ref;
  for (auto& x : later) x.t += 100.0;
  EXPECT_THROW(EvaluateTrajectory(ref, true, later, true, NoOutages()), std::invalid_argument);
}

// Relative error: a 1 % scale error on a straight drive is 1 % over every segment; on a circle the chord
// is shorter than the path, so the error is 1 % of chord / path.
TEST(TrajectoryMetrics, RelativeErrorOverDistance) {
  const auto ref = Drive(60.0, 0.125);  // 600 m straight, 1.25 m steps (exact in binary)
  auto scaled = ref;
  for (auto& x : scaled) x.p_w.x() *= 1.01;
  TrajectoryMetrics m = EvaluateTrajectory(ref, true, scaled, true, NoOutages());
  // Starts 0 ... 50 s reach 100 m further: 401 segments.
  EXPECT_EQ(m.segments, 401u);
  EXPECT_NEAR(m.rel_mean_pct, 1.0, 1e-6);
  EXPECT_NEAR(m.rel_rms_pct, 1.0, 1e-6);
  EXPECT_NEAR(m.rel_max_pct, 1.0, 1e-6);
  // 200 m segments: fewer of them, the same error.
  MetricOptions o;
  o.segment_length = 200.0;
  m = EvaluateTrajectory(ref, true, scaled, true, o);
  EXPECT_EQ(m.segments, 321u);
  EXPECT_NEAR(m.rel_mean_pct, 1.0, 1e-6);
  // A jump of 0.5 m at 30 s: segments across it see 0.5 m over 100 m (0.5 %), the others nothing.
  auto jump = ref;
  for (auto& x : jump) {
    if (x.t - kT0 >= 30.0) x.p_w.y() += 0.5;
  }
  m = EvaluateTrajectory(ref, true, jump, true, NoOutages());
  EXPECT_NEAR(m.rel_max_pct, 0.5, 1e-9);
  // Starts at 20 ... 29.875 s (80 of 401) end at or after 30 s.
  EXPECT_NEAR(m.rel_mean_pct, 0.5 * 80.0 / 401.0, 1e-9);
}

TEST(TrajectoryMetrics, RelativeErrorSkipsSegmentsAcrossGaps) {
  const auto ref = Drive(60.0, 0.125);
  std::vector<TrajectorySample> est;
  for (const auto& x : ref) {
    if (x.t - kT0 > 20.0 && x.t - kT0 < 23.0) continue;  // a 3 s hole (> 1 s)
    TrajectorySample y = x;
    y.p_w.x() *= 1.01;
    est.push_back(y);
  }
  const TrajectoryMetrics m = EvaluateTrajectory(ref, true, est, true, NoOutages());
  // Valid segments lie wholly before the hole (starts 0 ... 10 s: 81) or after it (23 ... 50 s: 217).
  EXPECT_EQ(m.segments, 81u + 217u);
  EXPECT_NEAR(m.rel_max_pct, 1.0, 1e-6);
}

TEST(TrajectoryMetrics, OutageDrift) {
  const auto ref = Drive(100.0, 0.125);
  // The estimate drifts north quadratically inside [20, 40] s (2 m at its end) and [60, 70] s (0.5 m),
  // and is exact elsewhere.
  auto est = ref;
  for (auto& x : est) {
    const double s = x.t - kT0;
    if (s >= 20.0 && s <= 40.0) x.p_w.y() += 2.0 * std::pow((s - 20.0) / 20.0, 2);
    if (s >= 60.0 && s <= 70.0) x.p_w.y() += 0.5 * std::pow((s - 60.0) / 10.0, 2);
  }
  MetricOptions o;
  o.outages = {{kT0 + 20.0, kT0 + 40.0, "config"}, {kT0 + 60.0, kT0 + 70.0, "log gap"},
               {kT0 + 200.0, kT0 + 210.0, "config"}};  // after the end: not scored
  const TrajectoryMetrics m = EvaluateTrajectory(ref, true, est, true, o);
  ASSERT_EQ(m.outages.size(), 3u);
  EXPECT_NEAR(m.outages[0].max_h, 2.0, 1e-9);
  EXPECT_NEAR(m.outages[0].t_max, kT0 + 40.0, 1e-9);
  EXPECT_NEAR(m.outages[0].final_h, 2.0, 1e-9);
  EXPECT_EQ(m.outages[0].samples, 161u);
  EXPECT_NEAR(m.outages[1].max_h, 0.5, 1e-9);
  EXPECT_EQ(m.outages[1].window.source, "log gap");
  EXPECT_EQ(m.outages[2].samples, 0u);
  EXPECT_EQ(m.outages_scored, 2u);
  EXPECT_NEAR(m.outage_rms, std::sqrt((4.0 + 0.25) / 2.0), 1e-9);
  EXPECT_NEAR(m.outage_max, 2.0, 1e-9);
  EXPECT_NEAR(m.max_h, 2.0, 1e-9);
}

TEST(TrajectoryMetrics, RmseOutsideOutagesLeavesOutWindowsAndTheirSettleTime) {
  const auto ref = Drive(100.0, 0.125);
  // 0.3 m north everywhere but in [20, 40] s (2 m), the 5 s after it (1 m) and [60, 75] s (4 m).
  auto est = ref;
  for (auto& x : est) {
    const double s = x.t - kT0;
    x.p_w.y() += (s >= 20.0 && s <= 40.0) ? 2.0 : (s > 40.0 && s <= 45.0) ? 1.0 : (s >= 60.0 && s <= 75.0) ? 4.0 : 0.3;
  }
  MetricOptions o;
  o.outages = {{kT0 + 60.0, kT0 + 70.0, "log gap"}, {kT0 + 20.0, kT0 + 40.0, "config"}};  // unsorted
  TrajectoryMetrics m = EvaluateTrajectory(ref, true, est, true, o);
  ASSERT_TRUE(m.rmse_h_outside.has_value());
  EXPECT_NEAR(*m.rmse_h_outside, 0.3, 1e-9);
  EXPECT_EQ(m.outside_samples, 801u - 201u - 121u);  // [20, 45] and [60, 75] s at 8 Hz left out
  EXPECT_DOUBLE_EQ(m.outage_settle, 5.0);
  EXPECT_NEAR(m.outages[1].max_h, 2.0, 1e-9);  // the drift is still the window's own

  // Without a settle time the 1 m after the first window counts (40 samples in (40, 45]) and the last 4 m
  // stretch (40 samples in (70, 75]).
  o.outage_settle = 0.0;
  m = EvaluateTrajectory(ref, true, est, true, o);
  EXPECT_EQ(m.outside_samples, 801u - 161u - 81u);
  EXPECT_NEAR(*m.rmse_h_outside, std::sqrt((479.0 * 0.09 + 40.0 * 1.0 + 40.0 * 16.0) / 559.0), 1e-9);

  // No windows: nothing to leave out, and no number.
  EXPECT_FALSE(EvaluateTrajectory(ref, true, est, true, NoOutages()).rmse_h_outside.has_value());
  // Every pair inside a window: no number either.
  o.outages = {{kT0 - 1.0, kT0 + 200.0, "config"}};
  m = EvaluateTrajectory(ref, true, est, true, o);
  EXPECT_EQ(m.outside_samples, 0u);
  EXPECT_FALSE(m.rmse_h_outside.has_value());
}

TEST(TrajectoryMetrics, MergeWindows) {
  const auto w = MergeWindows({{30.0, 40.0, "config"}, {10.0, 20.0, "config"}, {35.0, 50.0, "log gap"},
                               {50.0, 55.0, "config"}, {60.0, 61.0, "log gap"}});
  ASSERT_EQ(w.size(), 3u);
  EXPECT_EQ(w[0].begin, 10.0);
  EXPECT_EQ(w[0].end, 20.0);
  EXPECT_EQ(w[1].begin, 30.0);
  EXPECT_EQ(w[1].end, 55.0);
  EXPECT_EQ(w[1].source, "config+log gap");
  EXPECT_EQ(w[2].source, "log gap");
}

// Alignment recovers a known transform: the estimate is the reference moved by a rigid motion; aligned, the
// errors vanish and the fitted transform is its inverse.
TEST(TrajectoryMetrics, AlignmentRecoversAKnownTransform) {
  const auto ref = Drive(40.0, 0.125, 10.0);  // straight then circling: not degenerate for a yaw fit
  const Mat3 R_yaw = Eigen::AngleAxisd(0.4, Vec3::UnitZ()).toRotationMatrix();
  const Vec3 t(120.0, -35.0, 4.0);
  auto moved = ref;
  for (auto& x : moved) {
    x.p_w = R_yaw * x.p_w + t;
    x.q_wb = Quat(R_yaw) * x.q_wb;
    x.v_w = R_yaw * x.v_w;
  }
  MetricOptions o;
  EXPECT_GT(EvaluateTrajectory(ref, true, moved, true, o).rmse_h, 50.0);  // unaligned: large
  o.alignment = Alignment::kYaw;
  TrajectoryMetrics m = EvaluateTrajectory(ref, true, moved, true, o);
  EXPECT_LT(m.rmse_3d, 1e-9);
  EXPECT_LT(m.rmse_att_deg, 1e-6);
  EXPECT_LT(*m.rmse_vel, 1e-9);
  EXPECT_LT((m.align.R - R_yaw.transpose()).norm(), 1e-12);
  EXPECT_LT((m.align.t + R_yaw.transpose() * t).norm(), 1e-9);

  // A full rotation (with roll and pitch) needs SE(3); the yaw-only fit leaves an error.
  const Mat3 R = (Eigen::AngleAxisd(0.4, Vec3::UnitZ()) * Eigen::AngleAxisd(0.1, Vec3::UnitX()) *
                  Eigen::AngleAxisd(-0.05, Vec3::UnitY()))
                     .toRotationMatrix();
  auto tilted = ref;
  for (auto& x : tilted) {
    x.p_w = R * x.p_w + t;
    x.q_wb = Quat(R) * x.q_wb;
  }
  EXPECT_GT(EvaluateTrajectory(ref, true, tilted, false, o).rmse_3d, 0.1);
  o.alignment = Alignment::kSe3;
  m = EvaluateTrajectory(ref, true, tilted, false, o);
  EXPECT_LT(m.rmse_3d, 1e-8);
  EXPECT_LT(m.rmse_att_deg, 1e-6);
  EXPECT_LT((m.align.R - R.transpose()).norm(), 1e-10);
  EXPECT_EQ(m.alignment, Alignment::kSe3);
}

TEST(TrajectoryMetrics, AlignmentNames) {
  EXPECT_EQ(ParseAlignment("none"), Alignment::kNone);
  EXPECT_EQ(ParseAlignment("yaw"), Alignment::kYaw);
  EXPECT_EQ(ParseAlignment("se3"), Alignment::kSe3);
  EXPECT_EQ(AlignmentName(Alignment::kYaw), "yaw");
  EXPECT_THROW(ParseAlignment("sim3"), std::invalid_argument);
}

// ---- The streaming evaluator against a whole-trajectory oracle --------------------------------------------

// The metrics as they were computed before they streamed, over whole vectors (kept as the test oracle): all
// pairs first, the path length at every reference sample, then each metric over the pairs.
namespace oracle {

double MaxGap(const std::vector<TrajectorySample>& estimate, double max_gap) {
  if (estimate.size() < 2) return max_gap;
  std::vector<double> dt(estimate.size() - 1);
  for (size_t i = 1; i < estimate.size(); ++i) dt[i - 1] = estimate[i].t - estimate[i - 1].t;
  const auto mid = dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2);
  std::nth_element(dt.begin(), mid, dt.end());
  return std::max(max_gap, kMedianGapFactor * *mid);
}

std::vector<MatchedPair> Match(const std::vector<TrajectorySample>& reference,
                               const std::vector<TrajectorySample>& estimate, double max_gap) {
  std::vector<MatchedPair> pairs;
  size_t k = 0;
  for (size_t i = 0; i < reference.size(); ++i) {
    const TrajectorySample& r = reference[i];
    if (r.t < estimate.front().t || r.t > estimate.back().t) continue;
    while (k + 1 < estimate.size() && estimate[k + 1].t <= r.t) ++k;
    const TrajectorySample& a = estimate[k];
    MatchedPair m;
    m.ref_index = i;
    m.ref = r;
    if (a.t == r.t) {
      m.est = a;
    } else {
      const TrajectorySample& b = estimate[k + 1];
      const double span = b.t - a.t;
      if (span > max_gap) continue;
      const double f = (r.t - a.t) / span;
      m.est.t = r.t;
      m.est.p_w = (1.0 - f) * a.p_w + f * b.p_w;
      m.est.v_w = (1.0 - f) * a.v_w + f * b.v_w;
      m.est.q_wb = a.q_wb.slerp(f, b.q_wb);
    }
    pairs.push_back(m);
  }
  return pairs;
}

TrajectoryMetrics Evaluate(const std::vector<TrajectorySample>& reference, bool reference_has_velocity,
                           const std::vector<TrajectorySample>& estimate, bool estimate_has_velocity,
                           const MetricOptions& options) {
  const double max_gap = MaxGap(estimate, options.max_gap);
  std::vector<MatchedPair> pairs = Match(reference, estimate, max_gap);
  TrajectoryMetrics m;
  m.max_gap = max_gap;
  m.alignment = options.alignment;
  m.align = FitAlignment(pairs, options.alignment);
  if (options.alignment != Alignment::kNone) {
    const Quat q_align(m.align.R);
    for (MatchedPair& p : pairs) {
      p.est.p_w = m.align.R * p.est.p_w + m.align.t;
      p.est.q_wb = (q_align * p.est.q_wb).normalized();
      p.est.v_w = m.align.R * p.est.v_w;
    }
  }
  for (const TrajectorySample& r : reference) {
    m.reference_in_span += r.t >= estimate.front().t && r.t <= estimate.back().t;
  }
  const double n = static_cast<double>(pairs.size());
  double se = 0.0, sn = 0.0, su = 0.0, sum_h = 0.0, svel = 0.0, satt = 0.0, syaw = 0.0;
  std::vector<double> err_h(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    const MatchedPair& p = pairs[i];
    const Vec3 d = p.est.p_w - p.ref.p_w;
    se += d.x() * d.x();
    sn += d.y() * d.y();
    su += d.z() * d.z();
    err_h[i] = d.head<2>().norm();
    sum_h += err_h[i];
    if (err_h[i] > m.max_h) {
      m.max_h = err_h[i];
      m.t_max_h = p.ref.t;
    }
    svel += (p.est.v_w - p.ref.v_w).squaredNorm();
    satt += LogQuat<double>(p.ref.q_wb.conjugate() * p.est.q_wb).squaredNorm();
    const double dyaw = WrapAngle(YawOfXAxis<double>(p.est.q_wb.toRotationMatrix()) -
                                  YawOfXAxis<double>(p.ref.q_wb.toRotationMatrix()));
    syaw += dyaw * dyaw;
    m.max_heading_deg = std::max(m.max_heading_deg, std::abs(dyaw) * kRadToDeg);
  }
  m.samples = pairs.size();
  m.rmse_e = std::sqrt(se / n);
  m.rmse_n = std::sqrt(sn / n);
  m.rmse_v = std::sqrt(su / n);
  m.rmse_h = std::sqrt((se + sn) / n);
  m.rmse_3d = std::sqrt((se + sn + su) / n);
  m.mean_h = sum_h / n;
  if (reference_has_velocity && estimate_has_velocity) m.rmse_vel = std::sqrt(svel / n);
  m.rmse_att_deg = std::sqrt(satt / n) * kRadToDeg;
  m.rmse_heading_deg = std::sqrt(syaw / n) * kRadToDeg;

  m.segment_length = options.segment_length;
  std::vector<double> travelled(reference.size(), 0.0);
  for (size_t i = 1; i < reference.size(); ++i) {
    travelled[i] = travelled[i - 1] + (reference[i].p_w - reference[i - 1].p_w).norm();
  }
  std::vector<size_t> run(pairs.size(), 0);
  for (size_t i = 1; i < pairs.size(); ++i) {
    run[i] = run[i - 1] + (pairs[i].ref_index == pairs[i - 1].ref_index + 1 ? 0 : 1);
  }
  double rel_sum = 0.0, rel_sq = 0.0;
  size_t j = 0;
  for (size_t i = 0; i < pairs.size() && options.segment_length > 0.0; ++i) {
    const double start = travelled[pairs[i].ref_index];
    j = std::max(j, i + 1);
    while (j < pairs.size() && travelled[pairs[j].ref_index] - start < options.segment_length) ++j;
    if (j >= pairs.size()) break;
    if (run[j] != run[i]) continue;
    const double dist = travelled[pairs[j].ref_index] - start;
    const Vec3 d_est = pairs[j].est.p_w - pairs[i].est.p_w;
    const Vec3 d_ref = pairs[j].ref.p_w - pairs[i].ref.p_w;
    const double pct = 100.0 * (d_est - d_ref).norm() / dist;
    rel_sum += pct;
    rel_sq += pct * pct;
    m.rel_max_pct = std::max(m.rel_max_pct, pct);
    ++m.segments;
  }
  if (m.segments > 0) {
    m.rel_mean_pct = rel_sum / static_cast<double>(m.segments);
    m.rel_rms_pct = std::sqrt(rel_sq / static_cast<double>(m.segments));
  }

  double outage_sq = 0.0;
  for (const TimeWindow& w : options.outages) {
    OutageDrift o;
    o.window = w;
    for (size_t i = 0; i < pairs.size(); ++i) {
      if (pairs[i].ref.t < w.begin || pairs[i].ref.t > w.end) continue;
      if (o.samples == 0 || err_h[i] > o.max_h) {
        o.max_h = err_h[i];
        o.t_max = pairs[i].ref.t;
      }
      o.final_h = err_h[i];
      ++o.samples;
    }
    if (o.samples > 0) {
      ++m.outages_scored;
      outage_sq += o.max_h * o.max_h;
      m.outage_max = std::max(m.outage_max, o.max_h);
    }
    m.outages.push_back(o);
  }
  if (m.outages_scored > 0) m.outage_rms = std::sqrt(outage_sq / static_cast<double>(m.outages_scored));

  m.outage_settle = options.outage_settle;
  if (!options.outages.empty()) {
    double outside_sq = 0.0;
    for (size_t i = 0; i < pairs.size(); ++i) {
      const double t = pairs[i].ref.t;
      if (std::any_of(options.outages.begin(), options.outages.end(), [&](const TimeWindow& w) {
            return t >= w.begin && t <= w.end + options.outage_settle;
          })) {
        continue;
      }
      outside_sq += err_h[i] * err_h[i];
      ++m.outside_samples;
    }
    if (m.outside_samples > 0) m.rmse_h_outside = std::sqrt(outside_sq / static_cast<double>(m.outside_samples));
  }
  return m;
}

}  // namespace oracle

// Equal to 1e-12 relative (the same sums in the same order: in practice bit-identical).
void ExpectSameMetrics(const TrajectoryMetrics& a, const TrajectoryMetrics& b) {
  auto same = [](double x, double y, const char* what) {
    EXPECT_NEAR(x, y, 1e-12 * std::max(1.0, std::max(std::abs(x), std::abs(y)))) << what;
  };
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.reference_in_span, b.reference_in_span);
  same(a.max_gap, b.max_gap, "max_gap");
  same(a.rmse_3d, b.rmse_3d, "rmse_3d");
  same(a.rmse_h, b.rmse_h, "rmse_h");
  same(a.rmse_v, b.rmse_v, "rmse_v");
  same(a.rmse_e, b.rmse_e, "rmse_e");
  same(a.rmse_n, b.rmse_n, "rmse_n");
  same(a.mean_h, b.mean_h, "mean_h");
  same(a.max_h, b.max_h, "max_h");
  same(a.t_max_h, b.t_max_h, "t_max_h");
  ASSERT_EQ(a.rmse_vel.has_value(), b.rmse_vel.has_value());
  if (a.rmse_vel) same(*a.rmse_vel, *b.rmse_vel, "rmse_vel");
  same(a.rmse_att_deg, b.rmse_att_deg, "rmse_att_deg");
  same(a.rmse_heading_deg, b.rmse_heading_deg, "rmse_heading_deg");
  same(a.max_heading_deg, b.max_heading_deg, "max_heading_deg");
  same(a.segment_length, b.segment_length, "segment_length");
  EXPECT_EQ(a.segments, b.segments);
  same(a.rel_mean_pct, b.rel_mean_pct, "rel_mean_pct");
  same(a.rel_rms_pct, b.rel_rms_pct, "rel_rms_pct");
  same(a.rel_max_pct, b.rel_max_pct, "rel_max_pct");
  ASSERT_EQ(a.outages.size(), b.outages.size());
  for (size_t i = 0; i < a.outages.size(); ++i) {
    SCOPED_TRACE("outage " + std::to_string(i));
    EXPECT_EQ(a.outages[i].window.begin, b.outages[i].window.begin);
    EXPECT_EQ(a.outages[i].window.source, b.outages[i].window.source);
    EXPECT_EQ(a.outages[i].samples, b.outages[i].samples);
    same(a.outages[i].max_h, b.outages[i].max_h, "outage max_h");
    same(a.outages[i].t_max, b.outages[i].t_max, "outage t_max");
    same(a.outages[i].final_h, b.outages[i].final_h, "outage final_h");
  }
  EXPECT_EQ(a.outages_scored, b.outages_scored);
  same(a.outage_rms, b.outage_rms, "outage_rms");
  same(a.outage_max, b.outage_max, "outage_max");
  EXPECT_EQ(a.outside_samples, b.outside_samples);
  ASSERT_EQ(a.rmse_h_outside.has_value(), b.rmse_h_outside.has_value());
  if (a.rmse_h_outside) same(*a.rmse_h_outside, *b.rmse_h_outside, "rmse_h_outside");
  EXPECT_EQ(a.alignment, b.alignment);
  EXPECT_LT((a.align.R - b.align.R).norm(), 1e-12);
  EXPECT_LT((a.align.t - b.align.t).norm(), 1e-9);
}

// A 10 Hz reference over 600 s: a drive with turns, a 90 s standstill in the middle (the relative error's
// open segments pile up there), and a missing stretch of reference samples. The estimate: 25 Hz on its own
// clock (interpolated), exact reference times for a while, holes of 0.5 s (interpolated across) and 4 s
// (not), starting after the reference and ending before it; its errors a seeded random walk in position,
// noise in velocity and small random rotations.
struct Scenario {
  std::vector<TrajectorySample> reference, estimate;
};

Scenario MakeScenario() {
  Scenario sc;
  auto truth_at = [](double s) {
    TrajectorySample x;
    x.t = kT0 + s;
    // Stand still over [200, 290) s; otherwise 8 m/s on a slowly varying heading.
    const double moving = s < 200.0 ? s : std::max(200.0, s - 90.0);
    const double yaw = 0.4 * std::sin(moving / 40.0) + moving / 150.0;
    x.p_w = Vec3(8.0 * moving * std::cos(0.3), 8.0 * moving * std::sin(0.3) + 30.0 * std::sin(moving / 25.0),
                 1.0 + 0.5 * std::sin(moving / 60.0));
    x.q_wb = QuatFromYaw(yaw) * Quat(Eigen::AngleAxisd(0.01 * std::sin(s), Vec3::UnitX()));
    x.v_w = (s >= 200.0 && s < 290.0) ? Vec3::Zero() : Vec3(8.0 * std::cos(yaw), 8.0 * std::sin(yaw), 0.0);
    return x;
  };
  for (int k = 0; k <= 6000; ++k) {
    const double s = 0.1 * k;
    if (s > 400.0 && s < 403.0) continue;  // the reference's own gap
    sc.reference.push_back(truth_at(s));
  }
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 1.0);
  Vec3 walk = Vec3::Zero();
  for (int k = 0;; ++k) {
    double s = 5.013 + 0.04 * k;
    if (s > 590.0) break;
    if (s > 100.0 && s < 130.0) s = std::round(s * 10.0) / 10.0;  // on the reference's times
    if (s > 150.0 && s < 150.5) continue;                         // interpolated across
    if (s > 320.0 && s < 324.0) continue;                         // a gap: not evaluated
    if (!sc.estimate.empty() && s <= sc.estimate.back().t - kT0) continue;
    TrajectorySample x = truth_at(s);
    walk += 0.02 * Vec3(noise(rng), noise(rng), 0.3 * noise(rng));
    x.p_w += walk;
    x.v_w += 0.05 * Vec3(noise(rng), noise(rng), noise(rng));
    const Vec3 axis = Vec3(noise(rng), noise(rng), noise(rng)).normalized();
    x.q_wb = (x.q_wb * Quat(Eigen::AngleAxisd(0.004 * noise(rng), axis))).normalized();
    sc.estimate.push_back(x);
  }
  return sc;
}

// Unsorted and overlapping on purpose (MetricOptions does not require merged windows): one before the
// estimate, one across its 4 s gap, one in the standstill, one after its end, one holding a single
// reference time.
std::vector<TimeWindow> ScenarioOutages() {
  return {{kT0 + 310.0, kT0 + 340.0, "config"},  {kT0 + 1.0, kT0 + 4.0, "config"},
          {kT0 + 60.0, kT0 + 120.0, "log gap"},  {kT0 + 100.0, kT0 + 110.0, "config"},
          {kT0 + 210.0, kT0 + 250.0, "config"},  {kT0 + 595.0, kT0 + 600.0, "log gap"},
          {kT0 + 150.25, kT0 + 150.35, "config"}};
}

TEST(TrajectoryEvaluator, EqualsTheWholeTrajectoryOracle) {
  const Scenario sc = MakeScenario();
  for (Alignment alignment : {Alignment::kNone, Alignment::kYaw, Alignment::kSe3}) {
    for (double segment_length : {100.0, 7.0, 0.0}) {
      SCOPED_TRACE(AlignmentName(alignment) + ", segments of " + std::to_string(segment_length) + " m");
      MetricOptions o;
      o.alignment = alignment;
      o.segment_length = segment_length;
      o.outages = ScenarioOutages();
      o.outage_settle = segment_length == 7.0 ? 0.0 : 5.0;
      const TrajectoryMetrics want = oracle::Evaluate(sc.reference, true, sc.estimate, true, o);
      const TrajectoryMetrics got = EvaluateTrajectory(sc.reference, true, sc.estimate, true, o);
      ExpectSameMetrics(got, want);
      // The scenario exercises what it should.
      EXPECT_LT(got.samples, got.reference_in_span);  // the 4 s gap
      EXPECT_LT(got.reference_in_span, sc.reference.size());
      if (segment_length == 100.0) {
        EXPECT_GT(got.segments, 1000u);
      }
      EXPECT_EQ(got.outages[1].samples, 0u);
      EXPECT_GT(got.outages[4].samples, 300u);  // in the standstill
      EXPECT_EQ(got.outages[6].samples, 1u);    // one reference time, inside the 0.5 s hole
      EXPECT_GT(got.outside_samples, 1000u);
      EXPECT_LT(got.outside_samples + 300u, got.samples);
    }
  }
  // Without velocities on one side; the estimate as the reference of the other (an estimate vs an estimate).
  MetricOptions o;
  o.outages = ScenarioOutages();
  ExpectSameMetrics(EvaluateTrajectory(sc.reference, true, sc.estimate, false, o),
                    oracle::Evaluate(sc.reference, true, sc.estimate, false, o));
  ExpectSameMetrics(EvaluateTrajectory(sc.estimate, true, sc.reference, true, o),
                    oracle::Evaluate(sc.estimate, true, sc.reference, true, o));
}

// A keyframe-rate estimate (~1 Hz, a few longer intervals): interpolated across up to 3 × its median.
TEST(TrajectoryEvaluator, KeyframeRateEstimateEqualsTheOracle) {
  const Scenario sc = MakeScenario();
  std::vector<TrajectorySample> keyframes;
  for (const TrajectorySample& x : sc.estimate) {
    if (keyframes.empty() || x.t - keyframes.back().t >= (keyframes.size() % 7 == 0 ? 2.2 : 0.99)) {
      keyframes.push_back(x);
    }
  }
  MetricOptions o;
  o.outages = ScenarioOutages();
  const TrajectoryMetrics want = oracle::Evaluate(sc.reference, true, keyframes, false, o);
  const TrajectoryMetrics got = EvaluateTrajectory(sc.reference, true, keyframes, false, o);
  ExpectSameMetrics(got, want);
  EXPECT_GT(got.max_gap, 2.9);
}

// The evaluator fed sample by sample from sources (as `gins run` does from files) gives what the
// whole-vector call gives.
TEST(TrajectoryEvaluator, StreamedSampleBySampleEqualsEvaluateTrajectory) {
  const Scenario sc = MakeScenario();
  MetricOptions o;
  o.outages = ScenarioOutages();
  IntervalMedian intervals;
  for (const TrajectorySample& x : sc.estimate) intervals.Add(x.t);
  const double max_gap = EffectiveMaxGap(intervals, o.max_gap);
  TrajectoryEvaluator evaluator(VectorSource(sc.estimate), true, max_gap, o);
  const SampleSource reference = VectorSource(sc.reference);
  TrajectorySample r;
  while (reference(&r)) evaluator.AddReference(r);
  ExpectSameMetrics(evaluator.Metrics(), EvaluateTrajectory(sc.reference, true, sc.estimate, true, o));
  // Nothing evaluated: the same error as EvaluateTrajectory.
  TrajectoryEvaluator empty(VectorSource(sc.estimate), true, max_gap, o);
  EXPECT_THROW(empty.Metrics(), std::invalid_argument);
}

TEST(EstimateMatcher, PairRules) {
  std::vector<TrajectorySample> est(4);
  const double times[] = {10.0, 10.5, 11.0, 13.0};
  for (int k = 0; k < 4; ++k) {
    est[k].t = times[k];
    est[k].p_w = Vec3(times[k], 0.0, 0.0);
  }
  EstimateMatcher m(VectorSource(est), 1.0);
  TrajectorySample e;
  EXPECT_EQ(m.At(9.9, &e), EstimateMatcher::Result::kOutsideSpan);
  ASSERT_EQ(m.At(10.0, &e), EstimateMatcher::Result::kMatched);  // its own sample
  EXPECT_EQ(e.p_w.x(), 10.0);
  ASSERT_EQ(m.At(10.75, &e), EstimateMatcher::Result::kMatched);  // interpolated
  EXPECT_DOUBLE_EQ(e.p_w.x(), 10.75);
  EXPECT_EQ(e.t, 10.75);
  EXPECT_EQ(m.At(12.0, &e), EstimateMatcher::Result::kInGap);  // 2 s apart
  ASSERT_EQ(m.At(13.0, &e), EstimateMatcher::Result::kMatched);  // the last sample
  EXPECT_EQ(m.At(13.1, &e), EstimateMatcher::Result::kOutsideSpan);
}

TEST(IntervalMedian, ExactWithFewDistinctIntervals) {
  // Upper median of an even count, as nth_element at n/2: intervals {1, 1, 2, 5} -> 2.
  IntervalMedian m;
  EXPECT_FALSE(m.Median().has_value());
  for (double t : {0.0, 1.0, 2.0, 4.0, 9.0}) m.Add(t);
  EXPECT_EQ(*m.Median(), 2.0);
  // An IMU-rate clock printed to 1 µs at 1.7e9 s: the intervals' few distinct values, exactly.
  IntervalMedian imu;
  std::vector<TrajectorySample> samples;
  for (int k = 0; k < 20000; ++k) {
    TrajectorySample s;
    s.t = std::round((1700000000.0 + 0.01 * k) * 1e6) / 1e6;
    imu.Add(s.t);
    samples.push_back(s);
  }
  EXPECT_EQ(EffectiveMaxGap(samples, 0.0), oracle::MaxGap(samples, 0.0));
}

TEST(IntervalMedian, WithinAFractionOfAPerMilleWhenManyDistinct) {
  std::mt19937 rng(3);
  std::lognormal_distribution<double> interval(std::log(0.8), 0.6);
  std::vector<TrajectorySample> samples(1);
  IntervalMedian m;
  m.Add(0.0);
  for (int k = 0; k < 100000; ++k) {
    TrajectorySample s;
    s.t = samples.back().t + interval(rng);
    samples.push_back(s);
    m.Add(s.t);
  }
  const double exact = oracle::MaxGap(samples, 0.0) / kMedianGapFactor;
  EXPECT_NEAR(*m.Median(), exact, 5e-4 * exact);
  EXPECT_NE(*m.Median(), exact);  // really from the histogram
  EXPECT_NEAR(EffectiveMaxGap(samples, 0.0), kMedianGapFactor * exact, 1.5e-3 * exact);
}

}  // namespace
}  // namespace gins
