// Single-point positioning from one epoch's pseudoranges and the broadcast ephemerides: weighted least
// squares, iterated (Gauss-Newton), for the receiver's ECEF position and one receiver clock per system
// (each system's time and its receiver bias differ). The check that the satellite and atmosphere models
// (core/gnss_orbit.h, core/gnss_atmosphere.h) are right, and a first fix for a filter.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/gnss_atmosphere.h"
#include "core/gnss_orbit.h"

namespace gins {

// One satellite's code measurement(s) of an epoch.
struct SppObservation {
  SatelliteId sat;
  GnssSignal signal = GnssSignal::kGpsL1Ca;
  double pseudorange_m = 0.0;
  double cn0_dbhz = 0.0;  // 0: unknown
  // A second frequency, for the ionosphere-free combination (IonosphereModel::kIonosphereFree).
  bool has_second = false;
  GnssSignal signal2 = GnssSignal::kGpsL5;
  double pseudorange2_m = 0.0;
};

enum class IonosphereModel {
  kKlobuchar,        // broadcast GPS Klobuchar (alpha/beta), scaled by (f_L1/f)² to each signal
  kIonosphereFree,   // the combination where a second frequency exists, else none (σ no_ionosphere_sigma_m)
  kNone,             // no correction, σ no_ionosphere_sigma_m
};

struct SppOptions {
  double elevation_mask_rad = 15.0 * kDegToRad;
  IonosphereModel ionosphere = IonosphereModel::kKlobuchar;
  std::array<double, 4> klobuchar_alpha = {0.0, 0.0, 0.0, 0.0};
  std::array<double, 4> klobuchar_beta = {0.0, 0.0, 0.0, 0.0};
  bool troposphere = true;  // Saastamoinen, standard atmosphere, 1/sin(el)
  // Galileo's BGD applied to E1/E5 (the ICD's rule, GroupDelay). false: left out, as RTKLIB 2.4.3 b34's SPP
  // does (its residuals differ from ours by exactly c·BGD(E1,E5b), 1.5 m on this data); for comparisons.
  bool galileo_group_delay = true;
  PseudorangeSigmaModel sigma;
  // Error budget of a pseudorange, added in variance to sigma (RTKLIB pntpos's terms and values):
  double klobuchar_sigma_fraction = 0.5;  // of the Klobuchar delay (the model removes ~50 % rms)
  double no_ionosphere_sigma_m = 5.0;     // uncorrected ionosphere
  double troposphere_sigma_m = 0.3;       // × 1/(sin el + 0.1)
  double code_bias_sigma_m = 0.3;         // group delays left
  bool ephemeris_sigma = true;            // the record's URA/SISA (GPS, BeiDou: its URA class's bound)
  int max_iterations = 10;
  double converged_m = 1e-4;  // position and clock step
  EphemerisSelection selection;
};

// A satellite of the solution: its geometry and its fate.
struct SppSatellite {
  SatelliteId sat;
  bool used = false;
  std::string rejected;  // why not used: "no ephemeris" (none healthy and in date), "elevation"
  AzEl azel;
  double residual_m = 0.0;  // measured − predicted at the solution
  double sigma_m = 0.0;
  double ionosphere_m = 0.0, troposphere_m = 0.0;
};

struct SppSolution {
  bool ok = false;
  std::string why;  // when not ok
  Vec3 position_ecef_m = Vec3::Zero();
  std::map<GnssSystem, double> clock_m;  // receiver clock × c per system (system's own time)
  MatX covariance;  // of (x, y, z, clocks in the map's order), m²
  int iterations = 0;
  std::vector<SppSatellite> satellites;
};

// The prediction of one (corrected) pseudorange at a receiver state and its Jacobian.
struct PseudorangePrediction {
  double corrected_m = 0.0;  // the measurement with the satellite's group delay removed (or IF combined)
  double predicted_m = 0.0;  // |r_sat − r_rx| (Sagnac-rotated) + clock − c·Δt_sv + I + T
  Vec3 d_position = Vec3::Zero();  // ∂predicted/∂r_rx = −unit line of sight (atmosphere's and τ's neglected)
  double sigma_m = 0.0;
  AzEl azel;
  double ionosphere_m = 0.0, troposphere_m = 0.0;
  bool group_delay_known = true;
  TransmitState tx;  // the satellite at its transmit time (SatelliteAtTransmit), in the ECEF of reception
};
// Atmosphere and elevation are evaluated only when `rx_ecef_m` is on the Earth (|r| > 6000 km).
PseudorangePrediction PredictPseudorange(const KeplerEphemeris& eph, const SppObservation& obs, double rx_gps_s,
                                         const Vec3& rx_ecef_m, double rx_clock_m, const SppOptions& options);
PseudorangePrediction PredictPseudorange(const KeplerEphemeris& eph, const SppObservation& obs, double rx_gps_s,
                                         const ReceiverSite& rx, double rx_clock_m, const SppOptions& options);

// The fix of one epoch (`rx_gps_s`: the receiver's time tag, GPS seconds). `initial_ecef_m` may be zero
// (the Earth's centre: converges in ~6 iterations). Needs 3 + (systems) satellites above the mask.
SppSolution SolveSpp(double rx_gps_s, const std::vector<SppObservation>& observations,
                     const std::vector<KeplerEphemeris>& ephemerides, const SppOptions& options,
                     const Vec3& initial_ecef_m = Vec3::Zero());

}  // namespace gins
