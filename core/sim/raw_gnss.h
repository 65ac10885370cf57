// Raw GNSS observations (pseudorange, carrier phase, Doppler, C/N0 per signal) of a receiver on a known
// truth, from broadcast ephemerides: the input a tightly coupled estimator reads from a RINEX observation
// file (core/io/rinex_writer.h writes it), made with a known answer.
//
// The models (the satellite's orbit and clock are the broadcast ones, taken as the truth):
//   receiver clock  dt_r(t) = bias + ∫ drift, the drift a random walk (σ drift_rw·√Δt per epoch, the bias
//                   integrated by the trapezoid rule); the epoch's tag is t_rx = t + dt_r (a free-running
//                   receiver clock dates its epochs on its own time).
//   light time      τ = |r_sat − r_rx|/c iterated, r_sat = Rz(Ω_e·τ)·r_sat_ecef(t − τ): the satellite at
//                   the transmit time in the ECEF frame of reception (the Earth-rotation correction of
//                   SatelliteAtTransmit: EarthRotationCorrection with the system's Ω_e), ρ = |r_sat − r_rx|.
//   pseudorange     P = ρ + c·dt_r − c·(Δt_sv(t − τ) − GroupDelay(signal)) + I_s + T + ε + m
//                   (IS-GPS-200 §20.3.3.3.3: the SV clock, relativity included, minus the signal's group delay).
//   ionosphere      I_s = (f_L1/f)²·Klobuchar(α, β)·(1 + k_iono), k_iono ~ N(0, iono_residual_fraction) per
//                   satellite, constant (IS-GPS-200 §20.3.3.5.2.5; the first-order delay goes with 1/f²).
//   troposphere     T = SaastamoinenSlant·(1 + k_tropo), k_tropo ~ N(0, tropo_residual_fraction) per satellite.
//   code noise      ε ~ N(0, σ²), σ² = a² + b²/sin²(el): PseudorangeSigmaModel's (RTKLIB's a + b/sin(el)
//                   shape as its SPP weighs it), so SolveSpp's covariance is the true one when the rest is off.
//   multipath       m: first-order Gauss–Markov per satellite and signal, m_k = φ·m_{k−1} + √(1−φ²)·σ·n,
//                   φ = exp(−Δt/τ), started stationary when the satellite is acquired.
//   carrier phase   L = (ρ + c·dt_r − c·Δt_sv − I_s + T)/λ + N + ε_L/λ (cycles; the ionosphere advances the
//                   phase), N a random integer per satellite and signal, redrawn when the satellite is
//                   acquired again after it was not tracked (LLI bit 0 set at every new N).
//   Doppler         D = −(ρ̇ + c·(ḋt_r − ḋt_sv))/λ + ε_D/λ (Hz; positive when approaching, RINEX 3.04 §5.9),
//                   ρ̇ the exact time derivative of the light-time range above (raw_gnss.cc); the Sagnac
//                   rate is in the rotated r_sat and v_sat.
//   C/N0            cn0_a + cn0_b·sin(el) dB-Hz; SSI = clamp(cn0/6, 1, 9) (RINEX 3.04 §5.7).
//   mask, blocking  satellites below the mask are not seen; in a blocked window only the max_visible
//                   highest are (an urban canyon; 0: an outage).
// Randomness: one std::mt19937_64 per source (clock, code, multipath, Doppler, phase, ambiguity, atmosphere),
// each seeded from a master mt19937_64(seed); normals by Box–Muller from the raw bits (core/sim/simulator.h's
// convention); draws per satellite and signal are made whatever the σ, so a seed gives the same epochs bit
// for bit and changing one σ leaves the other sources' draws unchanged.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "core/conventions.h"
#include "core/gnss_orbit.h"
#include "core/io/rinex.h"
#include "core/sim/sim_random.h"

namespace gins {

// The code signal of a RINEX band and attribute ("1C", "2L", "7Q", ...) of a system; false if gins has no
// model for it. G: 1C L1 C/A; 2C 2D 2S 2L 2X 2P 2W L2; 5I 5Q 5X L5. E: 1B 1C 1X E1; 5I 5Q 5X E5a; 7I 7Q 7X E5b.
// C: 2I B1I; 7I B2I; 6I B3I; 1D 1P 1X B1C.
bool RinexSignal(GnssSystem system, const std::string& band_attribute, GnssSignal* signal);

struct RawGnssBlockedWindow {
  double start_s = 0.0;     // after the first simulated epoch
  double duration_s = 0.0;
  int max_visible = 0;      // satellites kept (the highest); 0: none
};

struct RawGnssSimOptions {
  // Band and attribute per system; each gives the codes C, L, D, S of that signal ("1C": C1C L1C D1C S1C).
  std::map<GnssSystem, std::vector<std::string>> signals = {
      {GnssSystem::kGps, {"1C", "2L"}}, {GnssSystem::kGalileo, {"1C", "7Q"}}, {GnssSystem::kBeidou, {"2I", "6I"}}};
  double elevation_mask_deg = 10.0;
  EphemerisSelection selection;  // Galileo I/NAV records by default (E1/E5b clock)
  // Receiver clock: offset at the first epoch, drift, random walk of the drift.
  double clock_bias_s = 1.0e-4, clock_drift_s_s = 5.0e-8, clock_drift_rw_s_s_sqrt_s = 1.0e-10;
  double code_sigma_a_m = 0.3, code_sigma_b_m = 0.3;         // σ² = a² + b²/sin²(el)
  double multipath_sigma_m = 0.3, multipath_tau_s = 20.0;     // Gauss–Markov; σ 0: none
  double doppler_sigma_m_s = 0.05;
  double phase_sigma_m = 0.003;
  double ambiguity_max_cycles = 1.0e6;  // N uniform in [−max, max]
  // Klobuchar α (s, s/sc, s/sc², s/sc³), β (s .. s/sc³). All zero: RTKLIB's built-in default set
  // (rtkcmn.c ion_default, 2004/1/1), so a nav file without GPSA/GPSB still gives a plausible delay.
  std::array<double, 4> klobuchar_alpha = {0.0, 0.0, 0.0, 0.0};
  std::array<double, 4> klobuchar_beta = {0.0, 0.0, 0.0, 0.0};
  bool ionosphere = true, troposphere = true;
  double iono_residual_fraction = 0.2, tropo_residual_fraction = 0.05;  // σ of k_iono, k_tropo
  double cn0_a_dbhz = 30.0, cn0_b_dbhz = 20.0;
  std::vector<RawGnssBlockedWindow> blocked;
  bool write_clock_offset = false;  // the true dt_r in the epoch line (a receiver writes its estimate, if any)

  // The α/β the simulator uses (the defaults above when both are zero).
  std::array<double, 4> Alpha() const;
  std::array<double, 4> Beta() const;
};

// The receiver antenna's true state at a true GPS time.
struct RawGnssTruth {
  double gps_s = 0.0;
  Vec3 r_rx_ecef_m = Vec3::Zero();
  Vec3 v_rx_ecef_m_s = Vec3::Zero();
};

// The codes per system in the order an epoch lists them: for each signal C, L, D, S.
std::map<GnssSystem, std::vector<std::string>> RawGnssObsTypes(const RawGnssSimOptions& options);

class RawGnssSimulator {
 public:
  // Throws std::invalid_argument for a signal RinexSignal does not know or options out of range.
  RawGnssSimulator(std::vector<KeplerEphemeris> ephemerides, const RawGnssSimOptions& options, uint64_t seed);

  // The epoch at a true state; truths in strictly increasing time. Satellites in id order, observations in
  // RawGnssObsTypes order. Satellites without a healthy ephemeris in date are not seen.
  RinexObsEpoch Simulate(const RawGnssTruth& truth);

  // The true receiver clock at the last epoch: offset (s) and drift (s/s).
  double clock_bias_s() const { return clock_bias_s_; }
  double clock_drift_s_s() const { return clock_drift_s_s_; }
  const RawGnssSimOptions& options() const { return options_; }

 private:
  using Rng = SimRng;  // core/sim/sim_random.h
  struct Signal {
    std::string band;  // "1C"
    GnssSignal signal;
  };
  struct Track {  // a satellite's state while it is tracked
    bool tracked = false;   // seen in the previous epoch
    std::vector<double> ambiguity_cycles, multipath_m;
  };
  struct Seen;  // one satellite's geometry at an epoch (raw_gnss.cc)

  bool Geometry(const KeplerEphemeris& eph, const RawGnssTruth& truth, Seen* seen) const;
  void AdvanceClock(double gps_s);
  void KeepVisible(double gps_s, std::vector<Seen>* seen) const;
  RinexSatelliteObs Observe(const Seen& s, double dt_s);

  std::vector<KeplerEphemeris> ephemerides_;
  RawGnssSimOptions options_;
  std::map<GnssSystem, std::vector<Signal>> signals_;
  std::vector<SatelliteId> satellites_;  // every satellite of the ephemerides, in id order
  Rng rng_clock_, rng_code_, rng_multipath_, rng_doppler_, rng_phase_, rng_ambiguity_, rng_atmosphere_;
  std::map<SatelliteId, double> iono_residual_, tropo_residual_;
  std::map<SatelliteId, Track> tracks_;
  bool started_ = false;
  double first_gps_s_ = 0.0, last_gps_s_ = 0.0;
  double clock_bias_s_ = 0.0, clock_drift_s_s_ = 0.0;
};

// A whole observation file: epochs at start_gps_s + k/rate_hz, k = 0, 1, ... while ≤ end_gps_s (true GPS
// times), the truth from `truth_at` (the antenna at a true GPS time). Epochs without a satellite are left
// out. The header: the codes of RawGnssObsTypes, APPROX POSITION the first truth, INTERVAL 1/rate, TIME OF
// FIRST OBS the first written epoch's tag. Written through an AtomicFile (no file if anything throws).
// Returns the number of epochs written.
struct RawGnssFileOptions {
  double start_gps_s = 0.0, end_gps_s = 0.0, rate_hz = 1.0;
  std::string marker_name = "GINS SIM";
};
size_t WriteSimulatedRinexObs(const std::string& path, RawGnssSimulator* simulator, const RawGnssFileOptions& file,
                              const std::function<RawGnssTruth(double gps_s)>& truth_at);

// `gins simulate`'s raw observations (simulate.raw_gnss_* keys): obs.rnx next to log.txt, the antenna of the
// truth trajectory (lever_arm_m) at the log's times taken as GPS seconds (start_time_s is a GPS time).
struct RawGnssSimConfig {
  bool enabled = false;
  std::string nav_file;  // RINEX 3 navigation file (its GPSA/GPSB, if any, are the true Klobuchar α/β)
  double rate_hz = 1.0;
  // Bands per system separated by blanks ("1C 2L"); empty: the system is not simulated. Replace
  // options.signals when the file is made (RawGnssSignalsFromText).
  std::string gps_signals = "1C 2L", galileo_signals = "1C 7Q", beidou_signals = "2I 6I";
  RawGnssSimOptions options;
};
// options.signals from the three texts (bands as given, unchecked: the simulator refuses unknown ones).
std::map<GnssSystem, std::vector<std::string>> RawGnssSignalsFromText(const RawGnssSimConfig& config);

}  // namespace gins
