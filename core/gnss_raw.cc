// Raw GNSS observations for the tightly coupled estimators (core/gnss_raw.h).
#include "core/gnss_raw.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <limits>
#include <numeric>

namespace gins {

std::vector<RawSatellite> PrepareSatellites(const RawGnssMeasurement& m, const Vec3& r_rx_ecef, size_t* skipped) {
  std::vector<RawSatellite> out;
  out.reserve(m.satellites.size());
  size_t left_out = 0;
  const RawGnssNav& nav = *m.nav;
  const ReceiverSite site(r_rx_ecef);
  for (const RawGnssObservation& o : m.satellites) {
    const KeplerEphemeris* eph = SelectEphemeris(nav.ephemerides, o.code.sat, m.rx_gps_s, nav.spp.selection);
    if (eph == nullptr) {
      ++left_out;
      continue;
    }
    const PseudorangePrediction p = PredictPseudorange(*eph, o.code, m.rx_gps_s, site, 0.0, nav.spp);
    if (!(p.azel.el >= nav.spp.elevation_mask_rad) || !std::isfinite(p.corrected_m)) {
      ++left_out;
      continue;
    }
    const TransmitState& tx = p.tx;
    RawSatellite s;
    s.sat = o.code.sat;
    s.r_sat_ecef = tx.sat.position_ecef_m;
    s.v_sat_ecef = tx.sat.velocity_ecef_m_s;
    s.elevation = p.azel.el;
    // predicted_m = range − c·Δt_sv + I + T at rx clock 0: what is not the geometric range is taken out.
    const double geometric = (s.r_sat_ecef - r_rx_ecef).norm();
    s.range_m = p.corrected_m - (p.predicted_m - geometric);
    s.range_sigma_m = p.sigma_m;
    s.clock_system = s.sat.system;
    const auto isb = m.inter_system_bias.find(s.sat.system);
    if (isb != m.inter_system_bias.end() && s.sat.system != m.clock_reference) {
      s.clock_system = m.clock_reference;
      s.range_m -= isb->second.first;
      s.range_sigma_m = std::hypot(s.range_sigma_m, isb->second.second);
    }
    if (o.has_doppler && std::isfinite(o.doppler_hz)) {
      // A RINEX Doppler is positive for an approaching satellite: range rate = −λ·D, and it carries the
      // receiver's clock drift less the satellite's (IS-GPS-200 §20.3.3.3.3.1's clock, differentiated).
      const double lambda = kSpeedOfLight / SignalFrequency(o.code.signal);
      s.has_rate = true;
      s.rate_m_s = -lambda * o.doppler_hz + kSpeedOfLight * tx.sat.clock_drift_s_s;
      s.rate_sigma_m_s = nav.doppler_sigma * (1.0 + 1.0 / std::sin(s.elevation));
    }
    if (o.has_phase && nav.use_phase && std::isfinite(o.phase_cycles) && o.phase_cycles != 0.0) {
      s.has_phase = true;
      s.phase_m = kSpeedOfLight / SignalFrequency(o.code.signal) * o.phase_cycles;
      s.phase_sigma_m = nav.phase_sigma * (1.0 + 1.0 / std::sin(s.elevation));
      s.lost_lock = (o.phase_lli & 1) != 0;
    }
    s.sat_clock_s = tx.sat.clock_bias_s;
    out.push_back(s);
  }
  if (skipped != nullptr) *skipped = left_out;
  return out;
}

double RangeResidual(const RawSatellite& s, const Vec3& r_rx_ecef, Vec3* u_ecef) {
  const Vec3 d = s.r_sat_ecef - r_rx_ecef;
  const double range = d.norm();
  if (u_ecef != nullptr) *u_ecef = d / range;
  return range - s.range_m;
}

double RateResidual(const RawSatellite& s, const Vec3& r_rx_ecef, const Vec3& v_rx_ecef, Vec3* u_ecef) {
  // The satellite is in the ECEF frame of reception (rotated by Ω·τ), so the line of sight and the
  // velocities there already hold the Sagnac rate; τ's own rate (ρ̇/c ~ 1e-5) is negligible.
  const Vec3 d = s.r_sat_ecef - r_rx_ecef;
  const Vec3 u = d / d.norm();
  if (u_ecef != nullptr) *u_ecef = u;
  return u.dot(s.v_sat_ecef - v_rx_ecef) - s.rate_m_s;
}

bool SolveDopplerVelocity(const std::vector<RawSatellite>& sats, const Vec3& r_rx_ecef, double w_max,
                          Vec3* v_rx_ecef, Mat3* cov, int* used) {
  std::vector<const RawSatellite*> in;
  for (const RawSatellite& s : sats) {
    if (s.has_rate) in.push_back(&s);
  }
  // rate = u·(v_sat − v_rx) + d: rows (−uᵀ, 1)·(v_rx, d) = rate − u·v_sat, whitened.
  while (in.size() >= 5) {
    const int n = static_cast<int>(in.size());
    Eigen::MatrixX4d A(n, 4);
    VecX b(n);
    for (int i = 0; i < n; ++i) {
      const Vec3 d = in[i]->r_sat_ecef - r_rx_ecef;
      const Vec3 u = d / d.norm();
      const double w = 1.0 / in[i]->rate_sigma_m_s;
      A.row(i) << -w * u.transpose(), w;
      b(i) = w * (in[i]->rate_m_s - u.dot(in[i]->v_sat_ecef));
    }
    const Eigen::Matrix4d N = A.transpose() * A;
    const Eigen::LDLT<Eigen::Matrix4d> ldlt(N);
    if (ldlt.info() != Eigen::Success) return false;
    const Eigen::Vector4d x = ldlt.solve(A.transpose() * b);
    const Eigen::Matrix4d Ninv = ldlt.solve(Eigen::Matrix4d::Identity());
    // Standardised residuals: e = b − A·x, cov(e) = I − A·N⁻¹·Aᵀ (whitened rows).
    const VecX e = b - A * x;
    int worst = -1;
    double worst_w = w_max;
    for (int i = 0; i < n; ++i) {
      const double q = 1.0 - A.row(i) * Ninv * A.row(i).transpose();
      const double wi = std::abs(e(i)) / std::sqrt(std::max(q, 1e-12));
      if (!(wi <= worst_w)) worst_w = wi, worst = i;
    }
    if (worst >= 0) {
      in.erase(in.begin() + worst);
      continue;
    }
    if (!x.allFinite()) return false;
    *v_rx_ecef = x.head<3>();
    *cov = Ninv.topLeftCorner<3, 3>();
    if (used != nullptr) *used = n;
    return true;
  }
  return false;
}

namespace {

// Each row's group as a column index 0..g−1, and the rows per group.
int GroupColumns(const std::vector<int>& group, const std::vector<int>& rows, std::vector<int>* column,
                 std::vector<int>* size) {
  std::map<int, int> index;
  column->resize(rows.size());
  size->clear();
  for (size_t k = 0; k < rows.size(); ++k) {
    auto [it, added] = index.emplace(group[rows[k]], static_cast<int>(index.size()));
    if (added) size->push_back(0);
    (*column)[k] = it->second;
    ++(*size)[it->second];
  }
  return static_cast<int>(index.size());
}

}  // namespace

std::vector<int> ScreenSatellites(const NuisanceRows& rows, const MatX& P, double w_max) {
  std::vector<int> keep(rows.r.size());
  std::iota(keep.begin(), keep.end(), 0);
  std::vector<int> column, size;
  while (!keep.empty()) {
    const int m = static_cast<int>(keep.size());
    const int g = GroupColumns(rows.group, keep, &column, &size);
    MatX H(m, rows.H.cols());
    VecX r(m);
    MatX C = MatX::Zero(m, g);
    for (int k = 0; k < m; ++k) {
      H.row(k) = rows.H.row(keep[k]);
      r(k) = rows.r(keep[k]);
      C(k, column[k]) = 1.0;
    }
    MatX S = H * P * H.transpose();
    for (int k = 0; k < m; ++k) S(k, k) += rows.variance(keep[k]);
    const Eigen::LLT<MatX> llt(S);
    if (llt.info() != Eigen::Success) break;  // nothing to test with: the update's own check decides
    const MatX SiC = llt.solve(C);
    const MatX N = C.transpose() * SiC;  // g×g, diagonal-dominant; each group has a row
    const Eigen::LDLT<MatX> n_ldlt(N);
    const VecX clock = n_ldlt.solve(SiC.transpose() * r);
    const VecX e = r - C * clock;
    const MatX Q = S - C * n_ldlt.solve(C.transpose());
    int worst = -1;
    double worst_w = w_max;
    for (int k = 0; k < m; ++k) {
      if (size[column[k]] < 2) continue;  // a lone row of its group: its clock absorbs it
      const double w = std::abs(e(k)) / std::sqrt(std::max(Q(k, k), 1e-12));
      if (!(w <= worst_w)) {  // a NaN is the worst
        worst_w = std::isfinite(w) ? w : std::numeric_limits<double>::infinity();
        worst = k;
      }
    }
    if (worst < 0) break;
    keep.erase(keep.begin() + worst);
  }
  return keep;
}

int DifferenceCount(const std::vector<int>& group) {
  std::vector<int> sorted = group;
  std::sort(sorted.begin(), sorted.end());
  return static_cast<int>(sorted.size() - (std::unique(sorted.begin(), sorted.end()) - sorted.begin()));
}

void DifferenceByGroup(const NuisanceRows& rows, VecX* r_d, MatX* H_d, MatX* R_d, int* groups_used) {
  const int n = static_cast<int>(rows.r.size());
  // The reference of each group: its row of least variance (the first of equals).
  std::map<int, int> reference;
  std::map<int, int> count;
  for (int i = 0; i < n; ++i) {
    ++count[rows.group[i]];
    auto it = reference.find(rows.group[i]);
    if (it == reference.end() || rows.variance(i) < rows.variance(it->second)) reference[rows.group[i]] = i;
  }
  std::vector<int> members;
  for (int i = 0; i < n; ++i) {
    if (reference[rows.group[i]] != i) members.push_back(i);
  }
  const int m = static_cast<int>(members.size());
  r_d->resize(m);
  H_d->resize(m, rows.H.cols());
  *R_d = MatX::Zero(m, m);
  for (int a = 0; a < m; ++a) {
    const int i = members[a];
    const int ref = reference[rows.group[i]];
    (*r_d)(a) = rows.r(i) - rows.r(ref);
    H_d->row(a) = rows.H.row(i) - rows.H.row(ref);
    for (int b = 0; b < m; ++b) {
      if (rows.group[members[b]] == rows.group[i]) (*R_d)(a, b) = rows.variance(ref);
    }
    (*R_d)(a, a) += rows.variance(i);
  }
  if (groups_used != nullptr) {
    int used = 0;
    for (const auto& [group, c] : count) used += c >= 2 ? 1 : 0;
    *groups_used = used;
  }
}

double PhaseRangeChange(const RawSatellite& now, const RawSatellite& prev) {
  return now.phase_m - prev.phase_m + kSpeedOfLight * (now.sat_clock_s - prev.sat_clock_s);
}

bool PhaseSlipped(const RawSatellite& now, const RawSatellite& prev, double dt) {
  if (now.lost_lock) return true;
  if (!now.has_rate || !prev.has_rate) return false;
  const double from_doppler = 0.5 * (now.rate_m_s + prev.rate_m_s) * dt;
  const double bound = 5.0 * std::hypot(now.rate_sigma_m_s, prev.rate_sigma_m_s) * dt + 0.05;
  return !(std::abs(PhaseRangeChange(now, prev) - from_doppler) <= bound);
}

std::map<std::string, RawSatellite> PhasesByName(const std::vector<RawSatellite>& sats) {
  std::map<std::string, RawSatellite> out;
  for (const RawSatellite& s : sats) {
    if (s.has_phase) out[s.sat.ToString()] = s;
  }
  return out;
}

std::vector<PhasePair> UnbrokenPhases(const std::vector<RawSatellite>& now,
                                      const std::map<std::string, RawSatellite>& prev, double dt, uint64_t* slips) {
  std::vector<PhasePair> pairs;
  for (const RawSatellite& s : now) {
    if (!s.has_phase) continue;
    const auto q = prev.find(s.sat.ToString());
    if (q == prev.end()) continue;
    if (PhaseSlipped(s, q->second, dt)) {
      ++*slips;
      continue;
    }
    pairs.push_back({&s, &q->second});
  }
  return pairs;
}

LinearConstraint3 CompressRows(const VecX& r_d, const MatX& H_d, const MatX& R_d, const Vec3& x0) {
  LinearConstraint3 c;
  c.z = x0;
  if (r_d.size() == 0) return c;
  const Eigen::LLT<MatX> llt(R_d);
  const MatX W = llt.matrixL().solve(H_d);
  const VecX e = llt.matrixL().solve(r_d);
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(W.transpose() * W);
  const Vec3 b = W.transpose() * e;
  const double largest = eig.eigenvalues().maxCoeff();
  for (int i = 0; i < 3; ++i) {
    const double lambda = eig.eigenvalues()(i);
    if (!(lambda > 1e-9 * largest)) continue;
    const Vec3 v = eig.eigenvectors().col(i);
    c.sqrt_info.row(c.rank++) = std::sqrt(lambda) * v.transpose();
    c.z -= v * (v.dot(b) / lambda);
  }
  return c;
}

}  // namespace gins
