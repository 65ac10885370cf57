// Raw GNSS observation simulator (core/sim/raw_gnss.h; the models are in its header comment).
#include "core/sim/raw_gnss.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "core/gnss_atmosphere.h"
#include "core/io/rinex_writer.h"

namespace gins {

namespace {

constexpr double kFrequencyL1Hz = 1575.42e6;
constexpr int kLightTimeIterations = 4;  // τ's error shrinks by ~ρ̇/c ≈ 3e-6 per iteration

// RTKLIB rtkcmn.c ion_default (2004/1/1): a plausible mid-latitude set when the nav file gives none.
constexpr std::array<double, 4> kDefaultAlpha = {0.1118E-07, -0.7451E-08, -0.5961E-07, 0.1192E-06};
constexpr std::array<double, 4> kDefaultBeta = {0.1167E+06, -0.2294E+06, -0.1311E+06, 0.1049E+07};

bool AllZero(const std::array<double, 4>& a) {
  return a[0] == 0.0 && a[1] == 0.0 && a[2] == 0.0 && a[3] == 0.0;
}

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("raw GNSS simulator: " + message);
}

bool FiniteNonNegative(double x) { return std::isfinite(x) && x >= 0.0; }

}  // namespace

bool RinexSignal(GnssSystem system, const std::string& b, GnssSignal* signal) {
  auto in = [&](std::initializer_list<const char*> list) {
    for (const char* s : list)
      if (b == s) return true;
    return false;
  };
  switch (system) {
    case GnssSystem::kGps:
      if (b == "1C") *signal = GnssSignal::kGpsL1Ca;
      else if (in({"2C", "2D", "2S", "2L", "2X", "2P", "2W"})) *signal = GnssSignal::kGpsL2;
      else if (in({"5I", "5Q", "5X"})) *signal = GnssSignal::kGpsL5;
      else return false;
      return true;
    case GnssSystem::kGalileo:
      if (in({"1B", "1C", "1X"})) *signal = GnssSignal::kGalileoE1;
      else if (in({"5I", "5Q", "5X"})) *signal = GnssSignal::kGalileoE5a;
      else if (in({"7I", "7Q", "7X"})) *signal = GnssSignal::kGalileoE5b;
      else return false;
      return true;
    case GnssSystem::kBeidou:
      if (b == "2I") *signal = GnssSignal::kBeidouB1I;
      else if (b == "7I") *signal = GnssSignal::kBeidouB2I;
      else if (b == "6I") *signal = GnssSignal::kBeidouB3I;
      else if (in({"1D", "1P", "1X"})) *signal = GnssSignal::kBeidouB1C;
      else return false;
      return true;
    case GnssSystem::kGlonass: case GnssSystem::kQzss: case GnssSystem::kSbas: case GnssSystem::kIrnss:
      return false;
  }
  return false;
}

std::array<double, 4> RawGnssSimOptions::Alpha() const {
  return AllZero(klobuchar_alpha) && AllZero(klobuchar_beta) ? kDefaultAlpha : klobuchar_alpha;
}
std::array<double, 4> RawGnssSimOptions::Beta() const {
  return AllZero(klobuchar_alpha) && AllZero(klobuchar_beta) ? kDefaultBeta : klobuchar_beta;
}

std::map<GnssSystem, std::vector<std::string>> RawGnssObsTypes(const RawGnssSimOptions& options) {
  std::map<GnssSystem, std::vector<std::string>> types;
  for (const auto& [system, bands] : options.signals) {
    for (const std::string& band : bands) {
      for (const char* kind : {"C", "L", "D", "S"}) types[system].push_back(kind + band);
    }
  }
  return types;
}

// One satellite's geometry, clock and atmosphere at an epoch.
struct RawGnssSimulator::Seen {
  SatelliteId sat;
  const KeplerEphemeris* eph = nullptr;
  double range_m = 0.0, range_rate_m_s = 0.0;
  double sv_clock_s = 0.0, sv_drift_s_s = 0.0;  // Δt_sv and its rate at the transmit time
  AzEl azel;
  double iono_l1_m = 0.0, tropo_m = 0.0;
};

RawGnssSimulator::RawGnssSimulator(std::vector<KeplerEphemeris> ephemerides, const RawGnssSimOptions& options,
                                   uint64_t seed)
    : ephemerides_(std::move(ephemerides)),
      options_(options),
      rng_clock_(DerivedSeed(seed, 0)),
      rng_code_(DerivedSeed(seed, 1)),
      rng_multipath_(DerivedSeed(seed, 2)),
      rng_doppler_(DerivedSeed(seed, 3)),
      rng_phase_(DerivedSeed(seed, 4)),
      rng_ambiguity_(DerivedSeed(seed, 5)),
      rng_atmosphere_(DerivedSeed(seed, 6)) {
  for (const auto& [system, bands] : options_.signals) {
    for (const std::string& band : bands) {
      Signal s{band, GnssSignal::kGpsL1Ca};
      Require(RinexSignal(system, band, &s.signal),
              std::string("no model for signal ") + static_cast<char>(system) + " " + band);
      signals_[system].push_back(s);
    }
  }
  const RawGnssSimOptions& o = options_;
  Require(std::isfinite(o.elevation_mask_deg) && o.elevation_mask_deg > -90.0 && o.elevation_mask_deg < 90.0,
          "elevation mask must be within (−90, 90) deg");
  Require(std::isfinite(o.clock_bias_s) && std::fabs(o.clock_bias_s) < 1.0 && std::isfinite(o.clock_drift_s_s),
          "clock bias must be within ±1 s, drift finite");
  for (double x : {o.clock_drift_rw_s_s_sqrt_s, o.code_sigma_a_m, o.code_sigma_b_m, o.multipath_sigma_m,
                   o.doppler_sigma_m_s, o.phase_sigma_m, o.ambiguity_max_cycles, o.iono_residual_fraction,
                   o.tropo_residual_fraction}) {
    Require(FiniteNonNegative(x), "noise σ, ambiguity range and residual fractions must be finite and >= 0");
  }
  Require(std::isfinite(o.multipath_tau_s) && o.multipath_tau_s > 0.0, "multipath τ must be > 0");
  Require(o.ambiguity_max_cycles <= 1e8, "ambiguity range at most 1e8 cycles (F14.3 holds the phase)");
  for (const RawGnssBlockedWindow& w : o.blocked) {
    Require(std::isfinite(w.start_s) && FiniteNonNegative(w.duration_s) && w.max_visible >= 0,
            "blocked windows need a finite start, duration >= 0 and max_visible >= 0");
  }
  for (const KeplerEphemeris& e : ephemerides_) {
    if (signals_.count(e.sat.system)) satellites_.push_back(e.sat);
  }
  std::sort(satellites_.begin(), satellites_.end());
  satellites_.erase(std::unique(satellites_.begin(), satellites_.end()), satellites_.end());
  // The per-satellite atmosphere residuals: two draws per satellite, in id order, whatever is seen later.
  for (const SatelliteId& sat : satellites_) {
    iono_residual_[sat] = o.iono_residual_fraction * rng_atmosphere_.Normal();
    tropo_residual_[sat] = o.tropo_residual_fraction * rng_atmosphere_.Normal();
  }
}

bool RawGnssSimulator::Geometry(const KeplerEphemeris& eph, const RawGnssTruth& truth, Seen* s) const {
  const double c = kSpeedOfLight;
  const double omega_e = OrbitConstants(eph.sat.system).omega_e_rad_s;
  const Vec3& r_rx_ecef = truth.r_rx_ecef_m;
  // Light time: τ = |Rz(Ω_e·τ)·r_sat_ecef(t − τ) − r_rx|/c by fixed-point iteration (a fixed count: the
  // same arithmetic on every run).
  double tau = 0.075;
  for (int i = 0; i < kLightTimeIterations; ++i) {
    const Vec3 r = EarthRotationCorrection(KeplerSatelliteState(eph, truth.gps_s - tau).position_ecef_m, omega_e, tau);
    tau = (r - r_rx_ecef).norm() / c;
  }
  const SatelliteState st = KeplerSatelliteState(eph, truth.gps_s - tau);
  const Vec3 r_sat_ecef = EarthRotationCorrection(st.position_ecef_m, omega_e, tau);
  const Vec3 v_sat_ecef = EarthRotationCorrection(st.velocity_ecef_m_s, omega_e, tau);
  Vec3 u_ecef;  // unit, receiver to satellite
  s->azel = SatelliteAzEl(r_rx_ecef, r_sat_ecef, &u_ecef);
  if (s->azel.el < options_.elevation_mask_deg * kDegToRad) return false;
  s->eph = &eph;
  s->sat = eph.sat;
  s->range_m = (r_sat_ecef - r_rx_ecef).norm();
  // ρ(t) = |R(Ω_e·τ)·r_sat(t − τ) − r_rx(t)| with τ = ρ/c. Its derivative: ρ̇ = A + τ̇·B with
  // A = u·(v_sat − v_rx) (v_sat rotated like r_sat) and B = −u·v_sat + Ω_e·u·(y_sat, −x_sat, 0) (the
  // transmit time and the rotation angle move with τ); τ̇ = ρ̇/c gives ρ̇ = A / (1 − B/c). B/c ≈ 3e-6:
  // a few mm/s on ρ̇, which a plain u·(v_sat − v_rx) leaves out.
  const double a = u_ecef.dot(v_sat_ecef - truth.v_rx_ecef_m_s);
  const double b = -u_ecef.dot(v_sat_ecef) + omega_e * u_ecef.dot(Vec3(r_sat_ecef.y(), -r_sat_ecef.x(), 0.0));
  s->range_rate_m_s = a / (1.0 - b / c);
  s->sv_clock_s = st.clock_bias_s;
  s->sv_drift_s_s = st.clock_drift_s_s;
  const GeodeticRad g = EcefToGeodeticRad(r_rx_ecef);
  s->iono_l1_m = !options_.ionosphere ? 0.0
                                      : KlobucharL1Delay(options_.Alpha(), options_.Beta(), g.lat, g.lon, s->azel.az,
                                                         s->azel.el, std::fmod(truth.gps_s, kSecondsPerWeek)) *
                                            (1.0 + iono_residual_.at(eph.sat));
  s->tropo_m = !options_.troposphere
                   ? 0.0
                   : SaastamoinenSlant(g.lat, g.h, s->azel.el) * (1.0 + tropo_residual_.at(eph.sat));
  return true;
}

void RawGnssSimulator::AdvanceClock(double gps_s) {
  if (!started_) {
    clock_bias_s_ = options_.clock_bias_s;
    clock_drift_s_s_ = options_.clock_drift_s_s;
    return;
  }
  // Random-walk drift, the bias integrating it (trapezoid).
  const double dt = gps_s - last_gps_s_;
  const double drift = clock_drift_s_s_ + options_.clock_drift_rw_s_s_sqrt_s * std::sqrt(dt) * rng_clock_.Normal();
  clock_bias_s_ += 0.5 * (clock_drift_s_s_ + drift) * dt;
  clock_drift_s_s_ = drift;
}

void RawGnssSimulator::KeepVisible(double gps_s, std::vector<Seen>* seen) const {
  const double elapsed = gps_s - first_gps_s_;
  size_t keep = seen->size();
  for (const RawGnssBlockedWindow& w : options_.blocked) {
    if (elapsed >= w.start_s && elapsed < w.start_s + w.duration_s) {
      keep = std::min(keep, static_cast<size_t>(w.max_visible));
    }
  }
  if (keep == seen->size()) return;
  // The highest satellites stay (ties by id, for a repeatable choice), then id order again.
  std::sort(seen->begin(), seen->end(), [](const Seen& x, const Seen& y) {
    return x.azel.el != y.azel.el ? x.azel.el > y.azel.el : x.sat < y.sat;
  });
  seen->resize(keep);
  std::sort(seen->begin(), seen->end(), [](const Seen& x, const Seen& y) { return x.sat < y.sat; });
}

RinexSatelliteObs RawGnssSimulator::Observe(const Seen& s, double dt_s) {
  const double c = kSpeedOfLight;
  const std::vector<Signal>& signals = signals_.at(s.sat.system);
  Track& track = tracks_[s.sat];
  const bool new_lock = !track.tracked;
  if (new_lock) {
    track.ambiguity_cycles.assign(signals.size(), 0.0);
    track.multipath_m.assign(signals.size(), 0.0);
  }
  track.tracked = true;
  const double sin_el = std::sin(s.azel.el);
  const double cn0 = options_.cn0_a_dbhz + options_.cn0_b_dbhz * sin_el;
  const int ssi = std::clamp(static_cast<int>(cn0 / 6.0), 1, 9);
  const PseudorangeSigmaModel sigma_model{options_.code_sigma_a_m, options_.code_sigma_b_m, 0.0, 45.0};
  const double code_sigma_m = sigma_model.Sigma(s.azel.el, cn0);
  const double phi = std::exp(-dt_s / options_.multipath_tau_s);
  RinexSatelliteObs out;
  out.sat = s.sat;
  for (size_t j = 0; j < signals.size(); ++j) {
    const double f_hz = SignalFrequency(signals[j].signal);
    const double lambda_m = c / f_hz;
    const double iono_m = s.iono_l1_m * (kFrequencyL1Hz / f_hz) * (kFrequencyL1Hz / f_hz);
    // A fixed number of draws per satellite and signal (one more uniform per new ambiguity).
    const double n_code = rng_code_.Normal(), n_multipath = rng_multipath_.Normal();
    const double n_doppler = rng_doppler_.Normal(), n_phase = rng_phase_.Normal();
    double& multipath_m = track.multipath_m[j];
    if (new_lock) {
      track.ambiguity_cycles[j] =
          std::round((2.0 * rng_ambiguity_.Uniform() - 1.0) * options_.ambiguity_max_cycles);
      multipath_m = options_.multipath_sigma_m * n_multipath;  // stationary start
    } else {
      multipath_m = phi * multipath_m + std::sqrt(1.0 - phi * phi) * options_.multipath_sigma_m * n_multipath;
    }
    const double group_delay_s = GroupDelay(*s.eph, signals[j].signal);
    // The geometric part and the clocks, common to code and phase.
    const double base_m = s.range_m + c * clock_bias_s_ - c * s.sv_clock_s + s.tropo_m;
    const double code_m = base_m + c * group_delay_s + iono_m + code_sigma_m * n_code + multipath_m;
    const double phase_cycles =
        (base_m - iono_m + options_.phase_sigma_m * n_phase) / lambda_m + track.ambiguity_cycles[j];
    const double doppler_hz =
        -(s.range_rate_m_s + c * (clock_drift_s_s_ - s.sv_drift_s_s) + options_.doppler_sigma_m_s * n_doppler) /
        lambda_m;
    const std::string& band = signals[j].band;
    out.obs.push_back({"C" + band, code_m, 0, ssi});
    out.obs.push_back({"L" + band, phase_cycles, new_lock ? 1 : 0, ssi});
    out.obs.push_back({"D" + band, doppler_hz, 0, ssi});
    out.obs.push_back({"S" + band, cn0, 0, ssi});
  }
  return out;
}

RinexObsEpoch RawGnssSimulator::Simulate(const RawGnssTruth& truth) {
  Require(std::isfinite(truth.gps_s) && truth.r_rx_ecef_m.allFinite() && truth.v_rx_ecef_m_s.allFinite(),
          "truth not finite");
  Require(!started_ || truth.gps_s > last_gps_s_, "truth times must increase");
  const double dt_s = started_ ? truth.gps_s - last_gps_s_ : 0.0;
  AdvanceClock(truth.gps_s);
  if (!started_) first_gps_s_ = truth.gps_s;
  started_ = true;
  last_gps_s_ = truth.gps_s;

  std::vector<Seen> seen;
  for (const SatelliteId& sat : satellites_) {
    const KeplerEphemeris* eph = SelectEphemeris(ephemerides_, sat, truth.gps_s, options_.selection);
    Seen s;
    if (eph && Geometry(*eph, truth, &s)) seen.push_back(s);
  }
  KeepVisible(truth.gps_s, &seen);
  // Satellites not seen lose lock: a new ambiguity when they come back.
  size_t k = 0;
  for (auto& [sat, track] : tracks_) {
    while (k < seen.size() && seen[k].sat < sat) ++k;
    if (k == seen.size() || seen[k].sat != sat) track.tracked = false;
  }
  RinexObsEpoch epoch;
  epoch.gps_s = truth.gps_s + clock_bias_s_;
  epoch.has_clock_offset = options_.write_clock_offset;
  epoch.receiver_clock_offset_s = options_.write_clock_offset ? clock_bias_s_ : 0.0;
  for (const Seen& s : seen) epoch.satellites.push_back(Observe(s, dt_s));
  return epoch;
}

std::map<GnssSystem, std::vector<std::string>> RawGnssSignalsFromText(const RawGnssSimConfig& config) {
  std::map<GnssSystem, std::vector<std::string>> signals;
  for (const auto& [system, text] : {std::pair<GnssSystem, const std::string*>{GnssSystem::kGps, &config.gps_signals},
                                     {GnssSystem::kGalileo, &config.galileo_signals},
                                     {GnssSystem::kBeidou, &config.beidou_signals}}) {
    size_t at = 0;
    while (at < text->size()) {
      const size_t begin = text->find_first_not_of(' ', at);
      if (begin == std::string::npos) break;
      const size_t end = std::min(text->find(' ', begin), text->size());
      signals[system].push_back(text->substr(begin, end - begin));
      at = end;
    }
  }
  return signals;
}

size_t WriteSimulatedRinexObs(const std::string& path, RawGnssSimulator* simulator, const RawGnssFileOptions& file,
                              const std::function<RawGnssTruth(double gps_s)>& truth_at) {
  Require(file.rate_hz > 0.0 && std::isfinite(file.rate_hz), "rate must be > 0");
  Require(std::isfinite(file.start_gps_s) && std::isfinite(file.end_gps_s), "time span not finite");
  RinexObsHeader header;
  header.obs_types = RawGnssObsTypes(simulator->options());
  header.file_system = header.obs_types.size() == 1 ? static_cast<char>(header.obs_types.begin()->first) : 'M';
  header.interval_s = 1.0 / file.rate_hz;
  RinexObsFileInfo info;
  info.marker_name = file.marker_name;
  info.run_by = "gins simulate";
  std::unique_ptr<RinexObsWriter> writer;
  for (uint64_t k = 0;; ++k) {
    const double t = file.start_gps_s + static_cast<double>(k) / file.rate_hz;
    if (t > file.end_gps_s + 1e-9) break;
    const RawGnssTruth truth = truth_at(t);
    if (k == 0) {
      header.has_approx_position = true;
      for (int i = 0; i < 3; ++i) header.approx_position_ecef_m[i] = truth.r_rx_ecef_m[i];
      header.first_obs_gps_s = t;  // used if no epoch is written
    }
    const RinexObsEpoch epoch = simulator->Simulate(truth);
    if (epoch.satellites.empty()) continue;
    if (!writer) {
      header.first_obs_gps_s = epoch.gps_s;
      writer = std::make_unique<RinexObsWriter>(path, header, info);
    }
    writer->Add(epoch);
  }
  if (!writer) writer = std::make_unique<RinexObsWriter>(path, header, info);
  writer->Commit();
  return writer->epochs();
}

}  // namespace gins
