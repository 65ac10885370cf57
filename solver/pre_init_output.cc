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

ImuEarthTerms TermsAt(const EarthModel& earth, const Vec3& p_w) {
  ImuEarthTerms terms;
  terms.g_w = earth.Gravity(p_w);
  terms.rate_w = earth.rate_w();
  return terms;
}

}  // namespace

void PreInitOutput::Add(const StateEstimate& s, bool keep, const StateCallback& forward,
                        const StateCallback& forward2) {
  if (forward) forward(s);
  if (forward2) forward2(s);
  last_forward_t_ = s.x.t;
  if (keep) kept_.push_back({s.x.t, s.sigma_v});
}

void PreInitOutput::Start(const InitResult& init, const StateCallback& forward, const StateCallback& forward2) {
  if (started_) return;  // a watchdog's re-initialisation: the log's start is written already
  started_ = true;
  from_standstill_ = init.start == "standstill";
  static_start_ = init.static_start;
  fit_start_ = init.fit_start;
  fit_end_ = init.x0;
  earth_ = init.earth;
  steps_.clear();
  const std::vector<ImuSample>& imu = init.fit_imu;
  for (size_t i = 1; i < imu.size(); ++i) {
    if (imu[i].t > imu[i - 1].t) steps_.push_back({HeldBetween(imu[i - 1], imu[i]), imu[i].t - imu[i - 1].t});
  }
  // The window's last sample may precede the completing fix: its reading is held up to it.
  if (!imu.empty() && fit_end_.t - imu.back().t > kSameTime) steps_.push_back({imu.back(), fit_end_.t - imu.back().t});
  if (steps_.empty() || imu.front().t != fit_start_.t || (!forward && !forward2)) return;
  const StateEstimate a = EstimateOf(fit_start_, init.fit_start_P), b = EstimateOf(fit_end_, init.P0);
  const double after = last_forward_t_ + kSameTime;
  EmitBridge(a, &b, steps_, TermsAt(earth_, a.x.p_wb), noise_, false, [&](const StateEstimate& s) {
    if (s.x.t <= after || s.x.t >= fit_end_.t - kSameTime) return;
    if (forward) forward(s);
    if (forward2) forward2(s);
  });
}

StateEstimate PreInitOutput::Carried(const StateEstimate& first, const NavState& fit_start, const NavState& fit_end) {
  const Quat q_fix = (first.x.q_wb * fit_end.q_wb.conjugate()).normalized();
  StateEstimate e = first;
  e.x.t = fit_start.t;
  e.x.q_wb = (first.x.q_wb * (fit_end.q_wb.conjugate() * fit_start.q_wb)).normalized();
  e.x.p_wb = first.x.p_wb - q_fix * (fit_end.p_wb - fit_start.p_wb);
  e.x.v_w = q_fix * fit_start.v_w;
  return e;
}

StateCallback PreInitOutput::TwoSided(const StateCallback& out) const {
  if (!out || !started_) return out;
  // The rest epochs of the initialisation's standstill, before the fit starts.
  auto epochs = std::make_shared<std::vector<Epoch>>();
  if (from_standstill_) {
    for (const Epoch& e : kept_) {
      if (e.t >= static_start_ - kSameTime && e.t < fit_start_.t - kSameTime) epochs->push_back(e);
    }
  }
  const bool bridge = !steps_.empty() && fit_end_.t - fit_start_.t > kSameTime;
  if (epochs->empty() && !bridge) return out;
  auto pending = std::make_shared<bool>(true);
  auto steps = std::make_shared<const std::vector<HeldImuSample>>(steps_);
  const NavState fit_start = fit_start_, fit_end = fit_end_;
  const EarthModel earth = earth_;
  const BridgeNoise noise = noise_;
  return [=](const StateEstimate& s) {
    if (*pending) {
      *pending = false;
      if (std::abs(s.x.t - fit_end.t) <= kSameTime) {
        const StateEstimate a = Carried(s, fit_start, fit_end);
        for (const Epoch& e : *epochs) {
          StateEstimate r = a;
          r.x.t = e.t;
          r.x.v_w.setZero();
          r.sigma_v = e.sigma_v;
          out(r);
        }
        if (bridge) EmitBridge(a, &s, *steps, TermsAt(earth, a.x.p_wb), noise, false, out);
      }
    }
    out(s);
  };
}

}  // namespace gins
