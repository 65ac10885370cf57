// The ESKF's tightly coupled GNSS updates (core/gnss_raw.h): per epoch, the pseudoranges and then the range
// rates of the satellites that pass their own test, differenced within their clock's group, in one
// iterated update each.
#include <cmath>
#include <optional>

#include "core/chi2.h"
#include "core/so3.h"
#include "solver/eskf.h"
#include "solver/eskf_raw_gnss.h"

namespace gins {

using eskf::Block;

namespace {

constexpr int kRateGroup = 0;  // range rates: one receiver oscillator, one drift for every system

// The antenna in ECEF at a nominal state, its velocity, and the Jacobians of both in w.
struct Antenna {
  Vec3 r_ecef, v_ecef;
  Mat3 R_ecef_w, dp_dtheta_w, dv_dtheta_w;  // ∂p_ant_w/∂δθ = −R_wb[l]×, ∂v_ant_w/∂δθ = −R_wb[ω×l]×
};

Antenna AntennaAt(const NavState& x, const Vec3& lever_b, const Vec3& omega_b, const RawGnssMeasurement& m) {
  Antenna a;
  const Mat3 R_wb = x.R_wb();
  const Vec3 turn_b = omega_b.cross(lever_b);
  a.R_ecef_w = m.R_ecef_w;
  a.r_ecef = m.origin_ecef + m.R_ecef_w * (x.p_wb + R_wb * lever_b);
  a.v_ecef = m.R_ecef_w * (x.v_w + R_wb * turn_b);
  a.dp_dtheta_w = -R_wb * Hat<double>(lever_b);
  a.dv_dtheta_w = -R_wb * Hat<double>(turn_b);
  return a;
}

int SystemGroup(GnssSystem system) { return 1 + static_cast<int>(system); }

// The items (satellites, or pairs of epochs) whose rows pass ScreenSatellites; the others counted against
// their satellite (sat_of(item)).
template <typename T, typename SatOf>
std::vector<T> Screened(const std::vector<T>& items, const NuisanceRows& rows, const MatX& P, double w_max,
                        SatOf sat_of, std::map<std::string, uint64_t>* rejected) {
  std::vector<bool> keep(items.size(), false);
  for (int k : ScreenSatellites(rows, P, w_max)) keep[k] = true;
  std::vector<T> out;
  for (size_t i = 0; i < items.size(); ++i) {
    if (keep[i]) {
      out.push_back(items[i]);
    } else {
      ++(*rejected)[sat_of(items[i])->sat.ToString()];
    }
  }
  return out;
}

}  // namespace

NuisanceRows RawGnssRows(const NavState& x, const Vec3& lever_b, const Vec3& omega_b, const RawGnssMeasurement& m,
                         const std::vector<const RawSatellite*>& list, bool rates) {
  const Antenna a = AntennaAt(x, lever_b, omega_b, m);
  NuisanceRows rows;
  const int n = static_cast<int>(list.size());
  rows.r.resize(n);
  rows.H = MatX::Zero(n, eskf::kDim);
  rows.variance.resize(n);
  rows.group.resize(n);
  for (int i = 0; i < n; ++i) {
    const RawSatellite& s = *list[i];
    Vec3 u;
    if (rates) {
      rows.r(i) = RateResidual(s, a.r_ecef, a.v_ecef, &u);
      const Eigen::RowVector3d d_w = -u.transpose() * a.R_ecef_w;  // ∂r/∂v_ant_w
      rows.H.block<1, 3>(i, eskf::Offset(Block::kV)) = d_w;
      rows.H.block<1, 3>(i, eskf::Offset(Block::kTheta)) = d_w * a.dv_dtheta_w;
      rows.variance(i) = s.rate_sigma_m_s * s.rate_sigma_m_s;
      rows.group[i] = kRateGroup;
    } else {
      rows.r(i) = RangeResidual(s, a.r_ecef, &u);
      const Eigen::RowVector3d d_w = -u.transpose() * a.R_ecef_w;  // ∂r/∂p_ant_w
      rows.H.block<1, 3>(i, eskf::Offset(Block::kP)) = d_w;
      rows.H.block<1, 3>(i, eskf::Offset(Block::kTheta)) = d_w * a.dp_dtheta_w;
      rows.variance(i) = s.range_sigma_m * s.range_sigma_m;
      rows.group[i] = SystemGroup(s.clock_system);
    }
  }
  return rows;
}

void Eskf::Use(const RawGnssMeasurement& m) {
  if (!initialized_ || m.t < nom_.x.t || !m.nav) return;
  Propagate(m.t);
  // The watchdog as for fixes, on the epoch's own single-point fix: its verdict before the epoch is used,
  // and the ranges' outcome after (a run of rejected epochs re-initialises from the fix).
  if (m.has_fix && WatchdogTakes(m.fix)) return;
  FlushCovariance();
  const Vec3 omega_b = BodyRate();
  const Antenna a = AntennaAt(nom_.x, sensors_.gnss.lever_b, omega_b, m);
  size_t skipped = 0;
  const std::vector<RawSatellite> sats = PrepareSatellites(m, a.r_ecef, &skipped);
  ++raw_.epochs;
  raw_.unusable += skipped;
  const std::optional<bool> ranges = UpdateRawGnss(m, sats, /*rates=*/false);
  bool reset = false;
  if (ranges && m.has_fix) {
    reset = WatchGnss(m.fix, *ranges);
  } else if (ranges) {
    watchdog_.Watch(m.t, *ranges);  // no fix to re-initialise from: the run goes on
  }
  if (m.has_fix) prev_fix_ = m.fix;
  if (reset) return;
  if (m.nav->use_doppler) UpdateRawGnss(m, sats, /*rates=*/true);
  if (m.nav->use_phase) UpdateRawPhase(m, sats);
}

std::optional<bool> Eskf::UpdateRawGnss(const RawGnssMeasurement& m, const std::vector<RawSatellite>& sats,
                                        bool rates) {
  const Vec3 omega_b = BodyRate();
  const Vec3& lever_b = sensors_.gnss.lever_b;
  std::vector<const RawSatellite*> in;
  for (const RawSatellite& s : sats) {
    if (!rates || s.has_rate) in.push_back(&s);
  }
  auto rows_at = [&](const NavState& x, const std::vector<const RawSatellite*>& list) {
    return RawGnssRows(x, lever_b, omega_b, m, list, rates);
  };
  MeasurementCounts& counts = rates ? raw_.rates : raw_.ranges;
  const NuisanceRows all = rows_at(nom_.x, in);
  const std::vector<const RawSatellite*> kept =
      Screened(in, all, MatX(P_), raw_.w_max, [](const RawSatellite* s) { return s; }, &raw_.satellite_rejected);
  if (!ScreeningKeptMost(kept.size(), in.size())) {
    counts.Reject("most_satellites_screened", m.t);
    return false;
  }
  VecX r_d;
  MatX H_d, R_d;
  DifferenceByGroup(rows_at(nom_.x, kept), &r_d, &H_d, &R_d);
  const int dof = static_cast<int>(r_d.size());
  if (dof == 0) {
    ++raw_.epochs_without_differences;
    return DifferenceCount(all.group) > 0 ? std::optional<bool>(false) : std::nullopt;
  }
  const Model<Eigen::Dynamic> model = [&] {
    VecX r;
    MatX H, R;
    DifferenceByGroup(rows_at(nom_.x, kept), &r, &H, &R);
    return Linearized<Eigen::Dynamic>{r, H};
  };
  if (!Update<Eigen::Dynamic>(model, R_d, Chi2Gate(sensors_.gnss.gate_probability, dof), &counts, m.t)) return false;
  raw_.satellites_used += kept.size();
  return true;
}

nlohmann::json Eskf::RawGnssCounts::ToJson() const {
  nlohmann::json j;
  j["ranges"] = ranges.ToJson();
  j["range_rates"] = rates.ToJson();
  j["phase_differences"] = phases.ToJson();
  j["phase_slips"] = phase_slips;
  j["satellites_used"] = satellites_used;
  j["satellites_rejected"] = satellite_rejected;
  j["satellites_unusable"] = unusable;  // no healthy ephemeris in date, or below the mask
  j["epochs_without_differences"] = epochs_without_differences;
  return j;
}

}  // namespace gins

namespace gins {

// Carrier phase differenced in time (core/gnss_raw.h, PhaseRangeChange) = ρ_k − ρ_k−1 + c·Δdt_r. ρ_k−1 is
// taken from the antenna now less the displacement since the previous epoch, and the displacement's error
// from the state now: δD = Δt·δv + ½Δt²·([f_w]×·R_wb·δθ + R_wb·δba) (the velocity error's own rate over the
// interval, δv̇ = −R[f]×δθ − R·δba). The receiver clock's change is one for every satellite: one group.
void Eskf::UpdateRawPhase(const RawGnssMeasurement& m, const std::vector<RawSatellite>& sats) {
  const double dt = m.t - phase_epoch_.t;
  const Vec3& lever_b = sensors_.gnss.lever_b;
  if (phase_epoch_.valid && dt > 0.0 && dt <= kMaxPhaseInterval) {
    const EskfNominal x0 = nom_;
    const Mat3 R0 = x0.x.R_wb();
    const Vec3 f_w = a_w_ - gravity();
    // The propagation's displacement of the body (the updates' corrections since taken out).
    const Vec3 D0 = x0.x.p_wb - phase_epoch_.p_wb - position_corrections_;
    const Vec3 lever_prev_w = phase_epoch_.q_wb * lever_b;
    std::vector<PhasePair> pairs = UnbrokenPhases(sats, phase_epoch_.sats, dt, &raw_.phase_slips);
    auto rows_at = [&](const EskfNominal& x) {
      const Vec3 d_theta = LogQuat<double>(x0.x.q_wb.conjugate() * x.x.q_wb);
      const Vec3 D = D0 + dt * (x.x.v_w - x0.x.v_w) +
                     0.5 * dt * dt * (Hat<double>(f_w) * R0 * d_theta + R0 * (x.x.ba - x0.x.ba));
      const Mat3 R_wb = x.x.R_wb();
      const Vec3 r_now = m.origin_ecef + m.R_ecef_w * (x.x.p_wb + R_wb * lever_b);
      const Vec3 r_prev = m.origin_ecef + m.R_ecef_w * (x.x.p_wb - D + lever_prev_w);
      NuisanceRows rows;
      const int n = static_cast<int>(pairs.size());
      rows.r.resize(n);
      rows.H = MatX::Zero(n, eskf::kDim);
      rows.variance.resize(n);
      rows.group.assign(n, 0);
      const Mat3 dD_dtheta = 0.5 * dt * dt * Hat<double>(f_w) * R0, dD_dba = 0.5 * dt * dt * R0;
      for (int i = 0; i < n; ++i) {
        const RawSatellite& s = *pairs[i].first;
        const RawSatellite& q = *pairs[i].second;
        const Vec3 a = s.r_sat_ecef - r_now, b = q.r_sat_ecef - r_prev;
        rows.r(i) = a.norm() - b.norm() - PhaseRangeChange(s, q);
        const Eigen::RowVector3d u_now = (a / a.norm()).transpose() * m.R_ecef_w;
        const Eigen::RowVector3d u_prev = (b / b.norm()).transpose() * m.R_ecef_w;
        // r_prev moves with p and against D; r_now with p and the lever's turn.
        rows.H.block<1, 3>(i, eskf::Offset(Block::kP)) = u_prev - u_now;
        rows.H.block<1, 3>(i, eskf::Offset(Block::kV)) = -dt * u_prev;
        rows.H.block<1, 3>(i, eskf::Offset(Block::kTheta)) =
            u_now * R_wb * Hat<double>(lever_b) - u_prev * dD_dtheta;
        rows.H.block<1, 3>(i, eskf::Offset(Block::kBa)) = -u_prev * dD_dba;
        rows.variance(i) = s.phase_sigma_m * s.phase_sigma_m + q.phase_sigma_m * q.phase_sigma_m;
      }
      return rows;
    };
    if (pairs.size() >= 2) {
      const NuisanceRows all = rows_at(nom_);
      const size_t offered = pairs.size();
      pairs = Screened(pairs, all, MatX(P_), raw_.w_max, [](const auto& p) { return p.first; },
                       &raw_.satellite_rejected);
      if (!ScreeningKeptMost(pairs.size(), offered)) {
        raw_.phases.Reject("most_satellites_screened", m.t);
      } else if (pairs.size() >= 2) {
        VecX r_d;
        MatX H_d, R_d;
        DifferenceByGroup(rows_at(nom_), &r_d, &H_d, &R_d);
        const Model<Eigen::Dynamic> model = [&] {
          VecX r;
          MatX H, R;
          DifferenceByGroup(rows_at(nom_), &r, &H, &R);
          return Linearized<Eigen::Dynamic>{r, H};
        };
        Update<Eigen::Dynamic>(model, R_d, Chi2Gate(sensors_.gnss.gate_probability, static_cast<int>(r_d.size())),
                               &raw_.phases, m.t);
      }
    }
  }
  // This epoch is the next one's previous.
  phase_epoch_.valid = true;
  phase_epoch_.t = m.t;
  phase_epoch_.p_wb = nom_.x.p_wb;
  phase_epoch_.q_wb = nom_.x.q_wb;
  phase_epoch_.sats = PhasesByName(sats);
  position_corrections_.setZero();
}

}  // namespace gins
