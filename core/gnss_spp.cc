// Single-point positioning (core/gnss_spp.h).
#include "core/gnss_spp.h"

#include <Eigen/Dense>
#include <cmath>

namespace gins {

namespace {

constexpr double kOnEarth = 6.0e6;  // m from the centre: atmosphere and mask make sense

// IS-GPS-200 §20.3.3.3.1.3: the URA index's upper bound (m); the record gives the nominal value.
double UraClassBound(double ura_m) {
  static const double kBounds[] = {2.4, 3.4, 4.85, 6.85, 9.65, 13.65, 24.0, 48.0, 96.0, 192.0, 384.0, 768.0,
                                   1536.0, 3072.0, 6144.0};
  for (double b : kBounds)
    if (ura_m <= b) return b;
  return 6144.0;
}

double EphemerisSigma(const KeplerEphemeris& eph) {
  if (eph.sat.system == GnssSystem::kGalileo) return eph.sv_accuracy_m;  // SISA, m
  return UraClassBound(eph.sv_accuracy_m);
}

}  // namespace

PseudorangePrediction PredictPseudorange(const KeplerEphemeris& eph, const SppObservation& obs, double rx_gps_s,
                                         const Vec3& rx_ecef_m, double rx_clock_m, const SppOptions& options) {
  return PredictPseudorange(eph, obs, rx_gps_s, ReceiverSite(rx_ecef_m), rx_clock_m, options);
}

PseudorangePrediction PredictPseudorange(const KeplerEphemeris& eph, const SppObservation& obs, double rx_gps_s,
                                         const ReceiverSite& rx, double rx_clock_m, const SppOptions& options) {
  const Vec3& rx_ecef_m = rx.ecef_m;
  PseudorangePrediction p;
  bool known1 = true, known2 = true;
  const double c = kSpeedOfLight;
  const double gd_scale = eph.sat.system == GnssSystem::kGalileo && !options.galileo_group_delay ? 0.0 : c;
  const double p1 = obs.pseudorange_m - gd_scale * GroupDelay(eph, obs.signal, &known1);
  const bool use_if = options.ionosphere == IonosphereModel::kIonosphereFree && obs.has_second;
  if (use_if) {
    const double p2 = obs.pseudorange2_m - gd_scale * GroupDelay(eph, obs.signal2, &known2);
    p.corrected_m = IonosphereFreeCombination(p1, SignalFrequency(obs.signal), p2, SignalFrequency(obs.signal2));
  } else {
    p.corrected_m = p1;
  }
  p.group_delay_known = known1 && known2;

  p.tx = SatelliteAtTransmit(eph, rx_gps_s, obs.pseudorange_m, rx_ecef_m);
  const TransmitState& tx = p.tx;
  const Vec3 d = tx.sat.position_ecef_m - rx_ecef_m;
  const double range = d.norm();
  p.d_position = -d / range;
  double var = 0.0;
  if (rx_ecef_m.norm() > kOnEarth) {
    p.azel = SatelliteAzEl(rx, tx.sat.position_ecef_m);
    const GeodeticRad& g = rx.geo;
    const double sin_el = std::sin(p.azel.el);
    if (options.troposphere) {
      p.troposphere_m = SaastamoinenSlant(g.lat, g.h, p.azel.el);
      var += std::pow(options.troposphere_sigma_m / (sin_el + 0.1), 2);
    }
    if (use_if) {
      // first-order ionosphere removed
    } else if (options.ionosphere == IonosphereModel::kKlobuchar) {
      const double f_ratio = 1575.42e6 / SignalFrequency(obs.signal);
      p.ionosphere_m = f_ratio * f_ratio *
                       KlobucharL1Delay(options.klobuchar_alpha, options.klobuchar_beta, g.lat, g.lon, p.azel.az,
                                        p.azel.el, std::fmod(rx_gps_s, kSecondsPerWeek));
      var += std::pow(options.klobuchar_sigma_fraction * p.ionosphere_m, 2);
    } else {
      var += std::pow(options.no_ionosphere_sigma_m, 2);
    }
    double s = options.sigma.Sigma(p.azel.el, obs.cn0_dbhz);
    if (use_if) s *= 3.0;  // the combination amplifies the code noise ~3× (L1/L2 2.98, L1/L5 2.59)
    var += s * s;
  } else {
    var += std::pow(options.sigma.Sigma(kPi / 2.0, obs.cn0_dbhz), 2) + std::pow(options.no_ionosphere_sigma_m, 2);
  }
  var += std::pow(options.code_bias_sigma_m, 2);
  if (options.ephemeris_sigma) var += std::pow(EphemerisSigma(eph), 2);
  p.sigma_m = std::sqrt(var);
  p.predicted_m = range + rx_clock_m - c * tx.sat.clock_bias_s + p.ionosphere_m + p.troposphere_m;
  return p;
}

SppSolution SolveSpp(double rx_gps_s, const std::vector<SppObservation>& observations,
                     const std::vector<KeplerEphemeris>& ephemerides, const SppOptions& options,
                     const Vec3& initial_ecef_m) {
  SppSolution sol;
  std::vector<const KeplerEphemeris*> ephs(observations.size(), nullptr);
  for (size_t i = 0; i < observations.size(); ++i) {
    ephs[i] = SelectEphemeris(ephemerides, observations[i].sat, rx_gps_s, options.selection);
    if (ephs[i]) sol.clock_m[observations[i].sat.system] = 0.0;
  }
  Vec3 r = initial_ecef_m;
  std::vector<PseudorangePrediction> pred(observations.size());
  std::vector<bool> use(observations.size(), false);
  for (int iter = 0; iter < options.max_iterations; ++iter) {
    sol.iterations = iter + 1;
    // Column of each system's clock, over the systems that have a satellite in use.
    std::map<GnssSystem, int> column;
    std::vector<int> rows;
    const ReceiverSite site(r);
    for (size_t i = 0; i < observations.size(); ++i) {
      use[i] = false;
      if (!ephs[i]) continue;
      const GnssSystem sys = observations[i].sat.system;
      pred[i] = PredictPseudorange(*ephs[i], observations[i], rx_gps_s, site, sol.clock_m[sys], options);
      if (r.norm() > kOnEarth && pred[i].azel.el < options.elevation_mask_rad) continue;
      use[i] = true;
      rows.push_back(static_cast<int>(i));
      if (!column.count(sys)) column[sys] = 3 + static_cast<int>(column.size());
    }
    const int n = 3 + static_cast<int>(column.size());
    if (static_cast<int>(rows.size()) < n) {
      sol.why = "too few satellites: " + std::to_string(rows.size()) + " for " + std::to_string(n) + " unknowns";
      return sol;
    }
    MatX h = MatX::Zero(rows.size(), n);
    VecX v(rows.size());
    for (size_t k = 0; k < rows.size(); ++k) {
      const int i = rows[k];
      const double w = 1.0 / pred[i].sigma_m;  // whitened rows
      h.block<1, 3>(k, 0) = w * pred[i].d_position.transpose();
      h(k, column[observations[i].sat.system]) = w;
      v(k) = w * (pred[i].corrected_m - pred[i].predicted_m);
    }
    const MatX info = h.transpose() * h;
    const Eigen::LDLT<MatX> ldlt(info);
    const VecX dx = ldlt.solve(h.transpose() * v);
    if (ldlt.info() != Eigen::Success || !dx.allFinite()) {
      sol.why = "singular geometry";
      return sol;
    }
    r += dx.head<3>();
    for (auto& [sys, col] : column) sol.clock_m[sys] += dx(col);
    sol.covariance = ldlt.solve(MatX::Identity(n, n));
    if (dx.norm() < options.converged_m) {
      sol.ok = true;
      break;
    }
  }
  if (!sol.ok) sol.why = "not converged in " + std::to_string(options.max_iterations) + " iterations";
  // Keep only the clocks solved for.
  for (auto it = sol.clock_m.begin(); it != sol.clock_m.end();) {
    bool any = false;
    for (size_t i = 0; i < observations.size(); ++i) any = any || (use[i] && observations[i].sat.system == it->first);
    it = any ? std::next(it) : sol.clock_m.erase(it);
  }
  sol.position_ecef_m = r;
  const ReceiverSite site(r);
  for (size_t i = 0; i < observations.size(); ++i) {
    SppSatellite s;
    s.sat = observations[i].sat;
    s.used = use[i];
    if (!ephs[i]) {
      s.rejected = "no ephemeris";
    } else {
      const auto clock = sol.clock_m.find(s.sat.system);
      const PseudorangePrediction p = PredictPseudorange(*ephs[i], observations[i], rx_gps_s, site,
                                                         clock == sol.clock_m.end() ? 0.0 : clock->second, options);
      s.azel = p.azel;
      s.residual_m = p.corrected_m - p.predicted_m;
      s.sigma_m = p.sigma_m;
      s.ionosphere_m = p.ionosphere_m;
      s.troposphere_m = p.troposphere_m;
      if (!use[i]) s.rejected = "elevation";
    }
    sol.satellites.push_back(s);
  }
  return sol;
}

}  // namespace gins
