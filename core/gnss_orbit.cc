// Broadcast-ephemeris satellite models (core/gnss_orbit.h).
#include "core/gnss_orbit.h"

#include <array>
#include <cmath>
#include <limits>

namespace gins {

GnssOrbitConstants OrbitConstants(GnssSystem system) {
  switch (system) {
    case GnssSystem::kGalileo:
      return {3.986004418e14, 7.2921151467e-5};
    case GnssSystem::kBeidou:
      return {3.986004418e14, 7.292115e-5};
    default:  // GPS, QZSS (IS-QZSS uses IS-GPS-200's), NavIC
      return {3.986005e14, 7.2921151467e-5};
  }
}

double WrapHalfWeek(double dt_s) {
  constexpr double kHalfWeek = 302400.0;
  if (dt_s > kHalfWeek) dt_s -= kSecondsPerWeek * std::ceil((dt_s - kHalfWeek) / kSecondsPerWeek);
  if (dt_s < -kHalfWeek) dt_s += kSecondsPerWeek * std::ceil((-kHalfWeek - dt_s) / kSecondsPerWeek);
  return dt_s;
}

bool IsBeidouGeo(const SatelliteId& sat) {
  return sat.system == GnssSystem::kBeidou && ((sat.prn >= 1 && sat.prn <= 5) || (sat.prn >= 59 && sat.prn <= 63));
}

double SolveKepler(double mean_anomaly_rad, double e) {
  double ecc = mean_anomaly_rad;
  // Newton on f(E) = E − e sin E − M: quadratic convergence; 1e-14 rad is 0.3 µm on the orbit.
  for (int i = 0; i < 30; ++i) {
    const double step = (ecc - e * std::sin(ecc) - mean_anomaly_rad) / (1.0 - e * std::cos(ecc));
    ecc -= step;
    if (std::abs(step) < 1e-14) break;
  }
  return ecc;
}

double RelativisticClockTerm(GnssSystem system, double e, double sqrt_a_sqrt_m, double eccentric_anomaly_rad) {
  const double f = -2.0 * std::sqrt(OrbitConstants(system).mu_m3_s2) / (kSpeedOfLight * kSpeedOfLight);
  return f * e * sqrt_a_sqrt_m * std::sin(eccentric_anomaly_rad);
}

SatelliteState KeplerSatelliteState(const KeplerEphemeris& eph, double gps_s) {
  const GnssOrbitConstants k = OrbitConstants(eph.sat.system);
  const double a = eph.sqrt_a_sqrt_m * eph.sqrt_a_sqrt_m;
  const double tk = WrapHalfWeek(gps_s - eph.toe_gps_s());
  const double n = std::sqrt(k.mu_m3_s2 / (a * a * a)) + eph.delta_n_rad_s;  // corrected mean motion
  const double m = eph.m0_rad + n * tk;
  const double ecc = SolveKepler(m, eph.e);
  const double sin_e = std::sin(ecc), cos_e = std::cos(ecc);
  const double one_minus = 1.0 - eph.e * cos_e;
  const double nu = std::atan2(std::sqrt(1.0 - eph.e * eph.e) * sin_e, cos_e - eph.e);  // true anomaly
  const double phi = nu + eph.omega_rad;                                                   // argument of latitude
  const double s2 = std::sin(2.0 * phi), c2 = std::cos(2.0 * phi);
  // Second harmonic perturbations.
  const double du = eph.cus_rad * s2 + eph.cuc_rad * c2;
  const double dr = eph.crs_m * s2 + eph.crc_m * c2;
  const double di = eph.cis_rad * s2 + eph.cic_rad * c2;
  const double u = phi + du;
  const double r = a * one_minus + dr;
  const double inc = eph.i0_rad + di + eph.idot_rad_s * tk;
  // Their rates: dE/dt = n/(1 − e cos E), dν/dt = dE/dt·√(1−e²)/(1 − e cos E).
  const double ecc_dot = n / one_minus;
  const double nu_dot = ecc_dot * std::sqrt(1.0 - eph.e * eph.e) / one_minus;
  const double u_dot = nu_dot * (1.0 + 2.0 * (eph.cus_rad * c2 - eph.cuc_rad * s2));
  const double r_dot = a * eph.e * sin_e * ecc_dot + 2.0 * nu_dot * (eph.crs_m * c2 - eph.crc_m * s2);
  const double inc_dot = eph.idot_rad_s + 2.0 * nu_dot * (eph.cis_rad * c2 - eph.cic_rad * s2);
  // In the orbital plane.
  const double xp = r * std::cos(u), yp = r * std::sin(u);
  const double xp_dot = r_dot * std::cos(u) - yp * u_dot;
  const double yp_dot = r_dot * std::sin(u) + xp * u_dot;

  const bool geo = IsBeidouGeo(eph.sat);
  // Longitude of the ascending node: in ECEF (Ω̇ − Ω̇e), or for BeiDou GEO in the inertial-at-toe frame (Ω̇).
  const double node_rate = geo ? eph.omega_dot_rad_s : eph.omega_dot_rad_s - k.omega_e_rad_s;
  const double node = eph.omega0_rad + node_rate * tk - k.omega_e_rad_s * eph.toe_s;
  const double sn = std::sin(node), cn = std::cos(node), si = std::sin(inc), ci = std::cos(inc);
  const double yc = yp * ci, yc_dot = yp_dot * ci - yp * si * inc_dot;
  Vec3 pos(xp * cn - yc * sn, xp * sn + yc * cn, yp * si);
  Vec3 vel(xp_dot * cn - yc_dot * sn - node_rate * pos.y(), xp_dot * sn + yc_dot * cn + node_rate * pos.x(),
           yp_dot * si + yp * ci * inc_dot);
  if (geo) {
    // B1I ICD §5.2.4.12: X = Rz(Ω̇e·tk)·Rx(−5°)·X_GK with Rx(φ) = [1 0 0; 0 cφ sφ; 0 −sφ cφ],
    // Rz(φ) = [cφ sφ 0; −sφ cφ 0; 0 0 1].
    const double phi_x = -5.0 * kDegToRad;
    Mat3 rx;
    rx << 1, 0, 0, 0, std::cos(phi_x), std::sin(phi_x), 0, -std::sin(phi_x), std::cos(phi_x);
    const double z = k.omega_e_rad_s * tk, sz = std::sin(z), cz = std::cos(z);
    Mat3 rz, rz_dot;
    rz << cz, sz, 0, -sz, cz, 0, 0, 0, 1;
    rz_dot << -sz, cz, 0, -cz, -sz, 0, 0, 0, 0;
    rz_dot *= k.omega_e_rad_s;
    const Vec3 p_geo = rx * pos;
    vel = rz * (rx * vel) + rz_dot * p_geo;
    pos = rz * p_geo;
  }

  SatelliteState s;
  s.position_ecef_m = pos;
  s.velocity_ecef_m_s = vel;
  const double dt = WrapHalfWeek(gps_s - eph.toc_gps_s);
  s.relativistic_s = RelativisticClockTerm(eph.sat.system, eph.e, eph.sqrt_a_sqrt_m, ecc);
  s.clock_bias_s = eph.af0_s + eph.af1_s_s * dt + eph.af2_s_s2 * dt * dt + s.relativistic_s;
  // d/dt of F·e·√A·sin E = F·e·√A·cos E·Ė.
  const double rel_dot = RelativisticClockTerm(eph.sat.system, eph.e, eph.sqrt_a_sqrt_m, ecc + kPi / 2.0) * ecc_dot;
  s.clock_drift_s_s = eph.af1_s_s + 2.0 * eph.af2_s_s2 * dt + rel_dot;
  return s;
}

bool IsGalileoInav(const KeplerEphemeris& eph) {
  const int sources = static_cast<int>(eph.codes_on_l2);
  return (sources & 0x5) != 0;
}

double SignalFrequency(GnssSignal signal) {
  switch (signal) {
    case GnssSignal::kGpsL2: return 1227.60e6;
    case GnssSignal::kGpsL5: case GnssSignal::kGalileoE5a: return 1176.45e6;
    case GnssSignal::kGalileoE5b: case GnssSignal::kBeidouB2I: return 1207.14e6;
    case GnssSignal::kBeidouB1I: return 1561.098e6;
    case GnssSignal::kBeidouB3I: return 1268.52e6;
    default: return 1575.42e6;  // GPS L1, Galileo E1, BeiDou B1C
  }
}

double GroupDelay(const KeplerEphemeris& eph, GnssSignal signal, bool* known) {
  constexpr double kF1 = 1575.42e6, kF2 = 1227.60e6, kF5a = 1176.45e6, kF5b = 1207.14e6;
  bool ok = true;
  double delay = 0.0;
  switch (signal) {
    case GnssSignal::kGpsL1Ca:
      delay = eph.tgd_s;
      break;
    case GnssSignal::kGpsL2:
      delay = (kF1 / kF2) * (kF1 / kF2) * eph.tgd_s;
      break;
    case GnssSignal::kGpsL5:
      ok = false;
      break;
    case GnssSignal::kGalileoE1:
      delay = IsGalileoInav(eph) ? eph.bgd_e5b_e1_s : eph.bgd_e5a_e1_s;
      break;
    case GnssSignal::kGalileoE5a:
      ok = !IsGalileoInav(eph);
      delay = ok ? (kF1 / kF5a) * (kF1 / kF5a) * eph.bgd_e5a_e1_s : 0.0;
      break;
    case GnssSignal::kGalileoE5b:
      ok = IsGalileoInav(eph);
      delay = ok ? (kF1 / kF5b) * (kF1 / kF5b) * eph.bgd_e5b_e1_s : 0.0;
      break;
    case GnssSignal::kBeidouB1I:
      delay = eph.tgd1_b1_b3_s;
      break;
    case GnssSignal::kBeidouB2I:
      delay = eph.tgd2_b2_b3_s;
      break;
    case GnssSignal::kBeidouB3I:
      break;
    case GnssSignal::kBeidouB1C:
      ok = false;
      break;
  }
  if (known) *known = ok;
  return delay;
}

double MaxEphemerisAge(GnssSystem system) {
  switch (system) {
    case GnssSystem::kGalileo:
      return 4.0 * 3600.0;
    case GnssSystem::kBeidou:
      return 6.0 * 3600.0;
    default:
      return 2.0 * 3600.0;
  }
}

const KeplerEphemeris* SelectEphemeris(const std::vector<KeplerEphemeris>& ephemerides, const SatelliteId& sat,
                                       double gps_s, const EphemerisSelection& selection) {
  const KeplerEphemeris* best = nullptr;
  double best_age = std::numeric_limits<double>::infinity();
  for (const KeplerEphemeris& eph : ephemerides) {
    if (eph.sat != sat || eph.health != 0.0) continue;
    if (sat.system == GnssSystem::kGalileo && IsGalileoInav(eph) != selection.galileo_inav) continue;
    const double age = std::abs(gps_s - eph.toe_gps_s());
    if (age <= MaxEphemerisAge(sat.system) && age < best_age) {
      best = &eph;
      best_age = age;
    }
  }
  return best;
}

Vec3 EarthRotationCorrection(const Vec3& r_ecef, double omega_e_rad_s, double travel_s) {
  const double theta = omega_e_rad_s * travel_s, s = std::sin(theta), c = std::cos(theta);
  return Vec3(c * r_ecef.x() + s * r_ecef.y(), -s * r_ecef.x() + c * r_ecef.y(), r_ecef.z());
}

namespace {

// The satellite at its transmit time, before the Earth's rotation: it does not depend on the receiver, and
// every iteration of an epoch's single-point solution and each estimator ask for the same one. Remembered
// per thread (the estimators may run on their own), the last kKnown asked for; a hit must match the record
// (its address and its identifying values) and the observation exactly, so it is the same computation.
struct AtTransmitTime {
  const KeplerEphemeris* eph = nullptr;
  SatelliteId sat;
  double toe_s = 0.0, toc_gps_s = 0.0, af0_s = 0.0, m0_rad = 0.0, rx_gps_s = 0.0, pseudorange_m = 0.0;
  SatelliteState state;
  double tx_gps_s = 0.0;
  bool Is(const KeplerEphemeris& e, double rx, double pr) const {
    return eph == &e && sat == e.sat && toe_s == e.toe_s && toc_gps_s == e.toc_gps_s && af0_s == e.af0_s &&
           m0_rad == e.m0_rad && rx_gps_s == rx && pseudorange_m == pr;
  }
};

const AtTransmitTime& SatelliteAtTransmitTime(const KeplerEphemeris& eph, double rx_gps_s, double pseudorange_m) {
  constexpr size_t kKnown = 128;  // two epochs of 64 signals
  thread_local std::array<AtTransmitTime, kKnown> known;
  thread_local size_t next = 0;
  for (const AtTransmitTime& k : known) {
    if (k.Is(eph, rx_gps_s, pseudorange_m)) return k;
  }
  AtTransmitTime& out = known[next];
  next = (next + 1) % kKnown;
  out = AtTransmitTime{&eph, eph.sat, eph.toe_s, eph.toc_gps_s, eph.af0_s, eph.m0_rad, rx_gps_s, pseudorange_m, {}, 0.0};
  // Transmit time by the satellite's clock first, then corrected by it: Δt_sv changes by < 1e-11 s per
  // iteration after two (its drift is < 1e-9).
  double tx = rx_gps_s - pseudorange_m / kSpeedOfLight;
  for (int i = 0; i < 3; ++i) {
    out.state = KeplerSatelliteState(eph, tx);
    tx = rx_gps_s - pseudorange_m / kSpeedOfLight - out.state.clock_bias_s;
  }
  out.state = KeplerSatelliteState(eph, tx);
  out.tx_gps_s = tx;
  return out;
}

}  // namespace

TransmitState SatelliteAtTransmit(const KeplerEphemeris& eph, double rx_gps_s, double pseudorange_m,
                                  const Vec3& receiver_ecef_m) {
  const double omega_e = OrbitConstants(eph.sat.system).omega_e_rad_s;
  TransmitState out;
  const AtTransmitTime& at = SatelliteAtTransmitTime(eph, rx_gps_s, pseudorange_m);
  out.sat = at.state;
  const double tx = at.tx_gps_s;
  out.tx_gps_s = tx;
  const Vec3 p_tx = out.sat.position_ecef_m, v_tx = out.sat.velocity_ecef_m_s;
  double tau = rx_gps_s - tx;
  if (receiver_ecef_m.squaredNorm() > 0.0) {
    // τ from the geometry in the frame of t_rx: converges in 2-3 steps (Ω̇e·τ·|r| ≈ 130 m changes τ by < 0.5 µs).
    for (int i = 0; i < 4; ++i) tau = (EarthRotationCorrection(p_tx, omega_e, tau) - receiver_ecef_m).norm() / kSpeedOfLight;
  }
  out.travel_s = tau;
  out.sat.position_ecef_m = EarthRotationCorrection(p_tx, omega_e, tau);
  out.sat.velocity_ecef_m_s = EarthRotationCorrection(v_tx, omega_e, tau);
  return out;
}

}  // namespace gins
