#include "solver/pre_init_output.h"

#include <cmath>
#include <memory>

#include "core/imu_kernel.h"

namespace gins {
namespace {

// The two-sided stream's first state must be the initialisation's (the fit's motion leads to it).
constexpr double kSameTime = 1e-6;  // s

StateEstimate EstimateOf(const NavState& x, const Mat15& P) {
  StateEstimate e;
  e.x = x;
  e.sigma_p = P.block<3, 3>(nav::kP, nav::kP).diagonal().cwiseSqrt();
  e.sigma_v = P.block<3, 3>(nav::kV, nav::kV).diagonal().cwiseSqrt();
  const Mat3 R_wb = x.R_wb();
  e.sigma_att = (R_wb * P.block<3, 3>(nav::kTheta, nav::kTheta) * R_wb.transpose()).diagonal().cwiseSqrt();
  return e;
}

// A covariance for a state known only by its σ (world axes): those on the diagonal, the biases' blocks
// taken from P (the fit's: the two-sided pass reports no bias σ).
Mat15 CovarianceOf(const StateEstimate& s, const Mat15& P) {
  Mat15 C = Mat15::Zero();
  C.block<3, 3>(nav::kP, nav::kP) = s.sigma_p.cwiseAbs2().asDiagonal();
  C.block<3, 3>(nav::kV, nav::kV) = s.sigma_v.cwiseAbs2().asDiagonal();
  const Mat3 R_wb = s.x.R_wb();
  const Mat3 att_w = s.sigma_att.cwiseAbs2().asDiagonal();
  C.block<3, 3>(nav::kTheta, nav::kTheta) = R_wb.transpose() * att_w * R_wb;  // right perturbation: body axes
  C.block<6, 6>(nav::kBg, nav::kBg) = P.block<6, 6>(nav::kBg, nav::kBg);
  return C;
}

ImuEarthTerms TermsAt(const EarthModel& earth, const Vec3& p_w) {
  ImuEarthTerms terms;
  terms.g_w = earth.Gravity(p_w);
  terms.rate_w = earth.rate_w();
  return terms;
}

}  // namespace

void PreInitOutput::Add(const StateEstimate& s, const StateCallback& forward, const StateCallback& forward2) {
  // After the first standstill the vehicle moved, with no attitude yet: what follows is written at the
  // initialisation, from the backward run, in time order.
  if (!rest_times_.empty() && s.x.t - rest_times_.back() > kBreak) first_standstill_over_ = true;
  rest_times_.push_back(s.x.t);
  if (first_standstill_over_) return;
  if (forward) forward(s);
  if (forward2) forward2(s);
  last_forward_t_ = s.x.t;
}

BackwardSpan PreInitOutput::Span(double from, double to) const {
  BackwardSpan span;
  span.from = from;
  span.earth = earth_;
  for (const ImuSample& s : pre_init_imu_) {
    if (s.t >= from && s.t < to) span.imu.push_back(s);
  }
  for (const GnssMeasurement& f : pre_init_fixes_) {
    if (f.t >= from && f.t < to) span.fixes.push_back(f);
  }
  // The standstills: runs of rest epochs (one per IMU sample).
  for (double t : rest_times_) {
    if (t < from) continue;
    if (t >= to - kSameTime) break;
    if (!span.rests.empty() && t - span.rests.back().second <= kBreak) {
      span.rests.back().second = t;
    } else {
      span.rests.push_back({t, t});
    }
  }
  return span;
}

void PreInitOutput::Start(const InitResult& init, const StateCallback& forward, const StateCallback& forward2) {
  if (started_) return;  // a watchdog's re-initialisation: the log's start is written already
  started_ = true;
  fit_start_ = init.fit_start;
  fit_end_ = init.x0;
  earth_ = init.earth;
  if (backward_) {
    P0_ = init.P0;
    pre_init_imu_ = init.pre_init_imu;
    pre_init_fixes_ = init.pre_init_fixes;
  }
  steps_.clear();
  const std::vector<ImuSample>& imu = init.fit_imu;
  for (size_t i = 1; i < imu.size(); ++i) {
    if (imu[i].t > imu[i - 1].t) steps_.push_back({HeldBetween(imu[i - 1], imu[i]), imu[i].t - imu[i - 1].t});
  }
  // The window's last sample may precede the completing fix: its reading is held up to it.
  if (!imu.empty() && fit_end_.t - imu.back().t > kSameTime) steps_.push_back({imu.back(), fit_end_.t - imu.back().t});
  if (!forward && !forward2) return;
  const StateEstimate a = EstimateOf(fit_start_, init.fit_start_P), b = EstimateOf(fit_end_, init.P0);
  // What came after the last state written, up to the fit's start, run backwards from there.
  if (backward_) {
    BackwardSpan span = Span(last_forward_t_ + kSameTime, fit_start_.t);
    span.start = a;
    span.P = init.fit_start_P;
    for (const StateEstimate& s : backward_(span)) {
      if (forward) forward(s);
      if (forward2) forward2(s);
      last_forward_t_ = s.x.t;
    }
  }
  if (steps_.empty() || imu.front().t != fit_start_.t) return;
  const double after = last_forward_t_ + kSameTime;
  EmitBridge(a, &b, steps_, TermsAt(earth_, a.x.p_wb), noise_, false, [&](const StateEstimate& s) {
    if (s.x.t <= after || s.x.t >= fit_end_.t - kSameTime) return;
    if (forward) forward(s);
    if (forward2) forward2(s);
  });
}

StateCallback PreInitOutput::TwoSided(const StateCallback& out) const {
  if (!out || !started_ || !backward_ || pre_init_fixes_.empty()) return out;
  // Everything before the first state, from the first fix on, run backwards from it.
  auto span = std::make_shared<BackwardSpan>(Span(pre_init_fixes_.front().t, fit_end_.t));
  auto pending = std::make_shared<bool>(true);
  const BackwardFiller filler = backward_;
  const Mat15 P0 = P0_;
  const double t_first = fit_end_.t;
  return [=](const StateEstimate& s) {
    if (*pending) {
      *pending = false;
      if (std::abs(s.x.t - t_first) <= kSameTime) {
        span->start = s;
        span->P = CovarianceOf(s, P0);
        for (const StateEstimate& b : filler(*span)) out(b);
      }
    }
    out(s);
  };
}

}  // namespace gins
