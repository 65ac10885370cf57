#include "solver/raw_gnss_attacher.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <utility>
#include <type_traits>

#include "core/chi2.h"
#include "core/so3.h"
#include "factors/raw_gnss_factor.h"
#include "solver/smoother_gate.h"

namespace gins {
namespace {

constexpr int kRateGroup = 0;  // range rates: one receiver oscillator, one drift for every system

RawGnssAttacher::PredictedAntenna AntennaAt(const Prediction& pred, const Vec3& lever_b, const RawGnssMeasurement& m,
                           const AttachContext& ctx) {
  RawGnssAttacher::PredictedAntenna a;
  const Mat3 R_wb = pred.x.R_wb();
  a.omega_b = ctx.BodyRate(pred.x);
  const Vec3 turn_b = a.omega_b.cross(lever_b);
  a.p_w = pred.x.p_wb + R_wb * lever_b;
  a.v_w = pred.x.v_w + R_wb * turn_b;
  a.r_ecef = m.origin_ecef + m.R_ecef_w * a.p_w;
  a.v_ecef = m.R_ecef_w * a.v_w;
  // Tangent (δp, δθ, δv), θ right-perturbed (core/conventions.h).
  const MatX cov = SubCovariance(ctx.keyframes.EstimatedTypes(), pred.cov, {BlockType::kPose, BlockType::kVelocity});
  Eigen::Matrix<double, 3, 9> J_p = Eigen::Matrix<double, 3, 9>::Zero(), J_v = J_p;
  J_p.leftCols<3>().setIdentity();
  J_p.middleCols<3>(3) = -R_wb * Hat<double>(lever_b);
  J_v.middleCols<3>(3) = -R_wb * Hat<double>(turn_b);
  J_v.rightCols<3>().setIdentity();
  a.P_p = J_p * cov * J_p.transpose();
  a.P_v = J_v * cov * J_v.transpose();
  return a;
}

}  // namespace

RawGnssAttacher::RawGnssAttacher(const GnssOptions& gnss, std::function<void(double, bool)> on_checked)
    : lever_b_(gnss.lever_b),
      gate_probability_(gnss.gate_probability),
      w_max_(std::sqrt(Chi2Gate(gnss.gate_probability, 1))),
      on_checked_(std::move(on_checked)) {
  // The Huber corner at the gate of a full-rank factor, as the fixes' (smoother_attachers.h).
  const double gate = Chi2Gate(gnss.gate_probability, 3);
  if (std::isfinite(gate)) loss_.reset(new ceres::HuberLoss(std::sqrt(gate)));
}

bool RawGnssAttacher::On(const RawGnssMeasurement& m, const AttachContext& ctx) {
  if (!m.nav) return false;
  const Prediction pred = ctx.predict(m.t);
  const PredictedAntenna a = AntennaAt(pred, lever_b_, m, ctx);
  size_t skipped = 0;
  const std::vector<RawSatellite> sats = PrepareSatellites(m, a.r_ecef, &skipped);
  ++epochs_;
  unusable_ += skipped;
  // Every epoch with phases is a keyframe: the chain of differences links consecutive epochs (a slip between
  // two is seen in the second), and the IMU's error in a displacement grows as Δt².
  const bool phases =
      m.nav->use_phase && std::any_of(sats.begin(), sats.end(), [](const RawSatellite& s) { return s.has_phase; });
  Anchor anchor;
  if (phases) anchor = ctx.keyframe(m.t);
  bool attached = AttachRows(m, sats, /*rates=*/false, pred, a, ctx, &anchor);
  if (m.nav->use_doppler) attached = AttachRows(m, sats, /*rates=*/true, pred, a, ctx, &anchor) || attached;
  if (phases) {
    attached = AttachPhases(m, sats, a, anchor, ctx) || attached;
  } else {
    phase_epoch_.kf = nullptr;
  }
  return attached;
}

bool RawGnssAttacher::Gate(const NuisanceRows& rows, const std::vector<const RawSatellite*>& in, const Mat3& P,
                           const Vec3& x0, double t, MeasurementCounts* counts, LinearConstraint3* c,
                           size_t* kept_n) {
  const std::vector<int> kept_rows = ScreenSatellites(rows, P, w_max_);
  std::vector<bool> keep(in.size(), false);
  NuisanceRows kept;
  const int k = static_cast<int>(kept_rows.size());
  kept.r.resize(k);
  kept.H.resize(k, 3);
  kept.variance.resize(k);
  for (int j = 0; j < k; ++j) {
    keep[kept_rows[j]] = true;
    kept.r(j) = rows.r(kept_rows[j]);
    kept.H.row(j) = rows.H.row(kept_rows[j]);
    kept.variance(j) = rows.variance(kept_rows[j]);
    kept.group.push_back(rows.group[kept_rows[j]]);
  }
  for (size_t i = 0; i < in.size(); ++i) {
    if (!keep[i]) ++satellite_rejected_[in[i]->sat.ToString()];
  }
  *kept_n = kept_rows.size();
  if (!ScreeningKeptMost(kept_rows.size(), in.size())) {
    counts->Reject("most_satellites_screened", t);
    c->rank = -1;
    return false;
  }
  VecX r_d;
  MatX H_d, R_d;
  DifferenceByGroup(kept, &r_d, &H_d, &R_d);
  const int dof = static_cast<int>(r_d.size());
  if (dof == 0) {
    c->rank = 0;
    return false;
  }
  const MatX S = H_d * P * H_d.transpose() + R_d;
  const Eigen::LLT<MatX> llt(S);
  const double chi2 = llt.info() == Eigen::Success ? r_d.dot(llt.solve(r_d)) : NAN;
  if (!(chi2 <= Chi2Gate(gate_probability_, dof))) {
    counts->Reject(std::isfinite(chi2) ? "chi2_gate" : "numerical", t);
    c->rank = -1;
    return false;
  }
  *c = CompressRows(r_d, H_d, R_d, x0);
  return true;
}

bool RawGnssAttacher::AttachRows(const RawGnssMeasurement& m, const std::vector<RawSatellite>& sats, bool rates,
                                 const Prediction& pred, const PredictedAntenna& a, const AttachContext& ctx,
                                 Anchor* anchor) {
  std::vector<const RawSatellite*> in;
  for (const RawSatellite& s : sats) {
    if (!rates || s.has_rate) in.push_back(&s);
  }
  // Rows in the antenna's position (rates: velocity) in w.
  NuisanceRows rows;
  const int n = static_cast<int>(in.size());
  rows.r.resize(n);
  rows.H.resize(n, 3);
  rows.variance.resize(n);
  rows.group.resize(n);
  for (int i = 0; i < n; ++i) {
    const RawSatellite& s = *in[i];
    Vec3 u;
    rows.r(i) = rates ? RateResidual(s, a.r_ecef, a.v_ecef, &u) : RangeResidual(s, a.r_ecef, &u);
    rows.H.row(i) = -u.transpose() * m.R_ecef_w;
    const double sigma = rates ? s.rate_sigma_m_s : s.range_sigma_m;
    rows.variance(i) = sigma * sigma;
    rows.group[i] = rates ? kRateGroup : 1 + static_cast<int>(s.clock_system);
  }
  MeasurementCounts& counts = rates ? rates_ : ranges_;
  LinearConstraint3 c;
  size_t kept = 0;
  if (!Gate(rows, in, rates ? a.P_v : a.P_p, rates ? a.v_w : a.p_w, m.t, &counts, &c, &kept)) {
    if (!rates && c.rank == 0) ++epochs_without_differences_;
    // Rejected: by the gate, or every difference screened away (none to make is no verdict).
    if (!rates && on_checked_ && (c.rank < 0 || DifferenceCount(rows.group) > 0)) on_checked_(m.t, false);
    return false;
  }
  if (!rates && on_checked_) on_checked_(m.t, true);
  if (anchor->kf == nullptr) *anchor = ctx.anchor(m.t);
  std::vector<BlockRef> blocks = {{anchor->kf, BlockType::kPose}, {anchor->kf, BlockType::kVelocity}};
  if (anchor->partial != nullptr) blocks.push_back({anchor->kf, BlockType::kBias});
  ceres::CostFunction* cost = nullptr;
  const auto make = [&](const auto& model) -> ceres::CostFunction* {
    using M = std::decay_t<decltype(model)>;
    if (anchor->partial == nullptr) return RawAtKeyframeFactor<M>::Create(model);
    return PreintAttachedFactor<M>::Create(anchor->partial, ctx.EarthTermsAt(pred.x.p_wb), model);
  };
  if (rates) {
    cost = make(RawRateAtTime{GnssVelocityAtTime{c.z, Vec3::Ones(), a.omega_b, lever_b_}, c.sqrt_info});
  } else {
    cost = make(RawRangeAtTime{GnssAtTime{c.z, Vec3::Ones(), lever_b_}, c.sqrt_info});
  }
  ctx.keyframes.AddMeasurement(cost, loss_.get(), blocks, Chi2Gate(gate_probability_, c.rank));
  ++counts.used;
  satellites_used_ += kept;  // as the ESKF counts: the ranges' and the rates'
  return true;
}

bool RawGnssAttacher::AttachPhases(const RawGnssMeasurement& m, const std::vector<RawSatellite>& sats,
                                   const PredictedAntenna& a, const Anchor& anchor, const AttachContext& ctx) {
  const double dt = m.t - phase_epoch_.t;
  const bool chained = phase_epoch_.kf != nullptr && dt > 0.0 && dt <= kMaxPhaseInterval;
  bool attached = false;
  if (chained && phase_epoch_.kf != anchor.kf) {
    const std::vector<PhasePair> pairs = UnbrokenPhases(sats, phase_epoch_.sats, dt, &phase_slips_);
    // Rows in the antenna's displacement D from the previous keyframe's (at its estimate now) to the
    // predicted one; the previous antenna's own error moves both ranges alike (by |δ|·|Δu| ~ 1e-7·|δ|).
    const NavState x_i = phase_epoch_.kf->State();
    const Vec3 p_i = x_i.p_wb + x_i.R_wb() * lever_b_;
    const Vec3 r_i = m.origin_ecef + m.R_ecef_w * p_i;
    const int n = static_cast<int>(pairs.size());
    NuisanceRows rows;
    rows.r.resize(n);
    rows.H.resize(n, 3);
    rows.variance.resize(n);
    rows.group.assign(n, 0);  // the receiver clock's change: one for every satellite
    std::vector<const RawSatellite*> in;
    for (int k = 0; k < n; ++k) {
      const RawSatellite& s = *pairs[k].first;
      const RawSatellite& q = *pairs[k].second;
      const Vec3 to_now = s.r_sat_ecef - a.r_ecef;
      rows.r(k) = to_now.norm() - (q.r_sat_ecef - r_i).norm() - PhaseRangeChange(s, q);
      rows.H.row(k) = -(to_now / to_now.norm()).transpose() * m.R_ecef_w;
      rows.variance(k) = s.phase_sigma_m * s.phase_sigma_m + q.phase_sigma_m * q.phase_sigma_m;
      in.push_back(&s);
    }
    // The displacement's error: the velocity's over the interval (the ESKF's leading term) and, when the
    // interval is one preintegration's, the IMU noise it integrated.
    Mat3 P_d = dt * dt * a.P_v;
    const Preintegration* preint = anchor.kf->preint.get();
    if (preint != nullptr && std::abs(preint->dt() - dt) <= 1e-6) {
      const Mat3 R_i = x_i.R_wb();
      P_d += R_i * preint->cov().topLeftCorner<3, 3>() * R_i.transpose();
    }
    LinearConstraint3 c;
    size_t kept = 0;
    if (n >= 2 && Gate(rows, in, P_d, a.p_w - p_i, m.t, &phases_, &c, &kept)) {
      ctx.keyframes.AddMeasurement(RawDisplacementFactor::Create(c.z, c.sqrt_info, lever_b_), loss_.get(),
                                   {{phase_epoch_.kf, BlockType::kPose}, {anchor.kf, BlockType::kPose}},
                                   Chi2Gate(gate_probability_, c.rank));
      ++phases_.used;
      attached = true;
    }
  }
  // This epoch is the next one's previous.
  phase_epoch_.kf = anchor.kf;
  phase_epoch_.t = m.t;
  phase_epoch_.sats = PhasesByName(sats);
  return attached;
}

void RawGnssAttacher::OnKeyframeLeaving(const Keyframe& kf) {
  if (phase_epoch_.kf == &kf) phase_epoch_.kf = nullptr;
}

void RawGnssAttacher::AddStats(nlohmann::json* stats) const {
  if (epochs_ == 0) return;
  nlohmann::json j;
  j["ranges"] = ranges_.ToJson();
  j["range_rates"] = rates_.ToJson();
  j["satellites_used"] = satellites_used_;
  j["satellites_rejected"] = satellite_rejected_;
  j["satellites_unusable"] = unusable_;  // no healthy ephemeris in date, or below the mask
  j["epochs_without_differences"] = epochs_without_differences_;
  j["phase_differences"] = phases_.ToJson();
  j["phase_slips"] = phase_slips_;
  (*stats)["gnss_raw"] = j;
}

}  // namespace gins
