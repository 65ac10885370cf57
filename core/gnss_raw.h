// Raw GNSS observations for the tightly coupled estimators: the signals gins takes from a RINEX epoch, each
// satellite's pseudorange and range rate predicted at a receiver state (satellite models: core/gnss_orbit.h;
// atmosphere: core/gnss_atmosphere.h; the error budget: core/gnss_spp.h's), and the receiver clocks
// eliminated. docs/estimators.md ("Tightly coupled GNSS") describes the whole; here is the contract.
//
// Receiver clocks. A receiver clock (one bias per system: each system's time and its receiver delays differ;
// one drift: one oscillator) is a nuisance re-estimated at every epoch: white, with no prior. That is exact for
// receivers whose clock jumps (u-blox, many others steer or reset it by milliseconds) and costs one
// measurement per system and epoch. It is done by differencing: within a system every pseudorange less the
// one of smallest σ (DifferenceByGroup), which removes the bias whatever its value, with the differences'
// correlated noise kept (R = D·diag(σ²)·Dᵀ).
//
// Gating. Each satellite is tested alone with the state's covariance (ScreenSatellites: Baarda's data
// snooping on the clock-free residuals), the worst first, until every standardised residual passes; then
// the epoch's differences go through the ordinary χ² gate of the update.
#pragma once

#include <map>
#include <memory>
#include <utility>
#include <string>
#include <vector>

#include "core/gnss_spp.h"
#include "core/measurements.h"
#include "core/sensors.h"

namespace gins {

// One satellite's observations of an epoch, as the estimators use them.
struct RawGnssObservation {
  SppObservation code;   // pseudorange(s) and C/N0 (code.signal is the first signal)
  bool has_doppler = false;
  double doppler_hz = 0.0;  // of code.signal's carrier; positive while the satellite approaches (RINEX)
  bool has_phase = false;
  double phase_cycles = 0.0;  // of code.signal's carrier
  int phase_lli = 0;          // RINEX loss of lock indicator (bit 0: lost lock since the last epoch)
};

// What an epoch's models need besides the observations: ephemerides and the model options.
struct RawGnssNav {
  std::vector<KeplerEphemeris> ephemerides;
  SppOptions spp;  // mask, ionosphere, σ budget (from GnssRawOptions and the navigation header: solver/raw_gnss_feed.h)
  double doppler_sigma = 0.1;  // m/s: σ = this·(1 + 1/sin el)
  bool use_doppler = true;
  double phase_sigma = 0.003;  // m: time-differenced phase σ = this·(1 + 1/sin el)
  bool use_phase = true;
  bool galileo_fnav = false;  // Galileo's clock from F/NAV (E1/E5a) records, else I/NAV (E1/E5b)
};

// One epoch for an estimator.
struct RawGnssMeasurement {
  double t = 0.0;         // of the reception, on the log's time (GPS seconds): the tag less the receiver clock
  double rx_gps_s = 0.0;  // the receiver's epoch tag (RINEX), for the satellite models
  std::shared_ptr<const RawGnssNav> nav;
  std::vector<RawGnssObservation> satellites;
  // Inter-system biases: each system's receiver clock less the reference system's (m; the pipeline's running
  // mean over the single-point fixes) and its σ. A system with one shares the reference's clock (its ranges
  // less the bias, its σ added); one without keeps a clock of its own.
  GnssSystem clock_reference = GnssSystem::kGps;
  std::map<GnssSystem, std::pair<double, double>> inter_system_bias;  // system -> (bias, σ), m
  // The world frame w in ECEF: r_ecef = origin_ecef + R_ecef_w·p_w (core/geodesy.h).
  Vec3 origin_ecef = Vec3::Zero();
  Mat3 R_ecef_w = Mat3::Identity();
  // The epoch's own single-point fix and Doppler velocity, in w: the initialiser's input, and the loosely
  // coupled fallback of an estimator without raw updates.
  bool has_fix = false;
  GnssMeasurement fix;
  bool has_velocity = false;
  GnssVelocityMeasurement velocity;
};

// A satellite at an epoch, its models evaluated at a receiver position: what stays fixed while an update
// iterates (the satellite at transmit, the atmosphere, σ), and the measurement less them.
struct RawSatellite {
  SatelliteId sat;
  GnssSystem clock_system = GnssSystem::kGps;  // whose receiver clock its range carries (after the bias)
  Vec3 r_sat_ecef = Vec3::Zero();  // at transmit, in the ECEF frame of reception (Sagnac)
  Vec3 v_sat_ecef = Vec3::Zero();
  double elevation = 0.0;
  // Pseudorange with the satellite clock, group delay, ionosphere and troposphere taken out: the geometric
  // range plus the receiver clock (m), and its σ.
  double range_m = 0.0;
  double range_sigma_m = 0.0;
  // Range rate from the Doppler with the satellite's clock drift taken out: the geometric range rate plus
  // the receiver's clock drift (m/s), and its σ.
  bool has_rate = false;
  double rate_m_s = 0.0;
  double rate_sigma_m_s = 0.0;
  // Carrier phase (m: λ·cycles, its ambiguity unknown) for the time differences, the satellite clock at
  // transmit (s) that a difference removes, and whether the receiver lost lock since its last epoch.
  bool has_phase = false;
  double phase_m = 0.0;
  double phase_sigma_m = 0.0;
  double sat_clock_s = 0.0;
  bool lost_lock = false;
};

// The usable satellites of an epoch (ephemeris healthy and in date, above the mask) at a receiver position
// (ECEF, m; the atmosphere and mask there). *skipped counts the others.
std::vector<RawSatellite> PrepareSatellites(const RawGnssMeasurement& m, const Vec3& r_rx_ecef,
                                            size_t* skipped = nullptr);

// Predicted − measured for one satellite, without the receiver clock: |r_sat − r_rx| − range_m (Earth
// rotation during the travel is already in r_sat); and the unit line of sight u (receiver to satellite),
// the residual's gradient with respect to r_rx being −uᵀ.
double RangeResidual(const RawSatellite& s, const Vec3& r_rx_ecef, Vec3* u_ecef);
// Predicted − measured range rate, without the clock drift: u·(v_sat − v_rx) plus the Sagnac rate, less
// rate_m_s; its gradient with respect to v_rx is −uᵀ (u from RangeResidual's geometry).
double RateResidual(const RawSatellite& s, const Vec3& r_rx_ecef, const Vec3& v_rx_ecef, Vec3* u_ecef);

// The receiver's velocity (ECEF) from the range rates at a known position: weighted least squares for it and
// the clock drift, the satellite of the largest standardised residual beyond w_max dropped and the rest
// solved again while 5 or more remain. False with fewer than 5 range rates. *cov: the velocity's (m²/s²).
bool SolveDopplerVelocity(const std::vector<RawSatellite>& sats, const Vec3& r_rx_ecef, double w_max,
                          Vec3* v_rx_ecef, Mat3* cov, int* used = nullptr);

// Carrier phase differenced in time between two epochs of one satellite (each estimator's TDCP): the range's
// change plus the receiver clock's, λ·(φ_now − φ_prev) + c·(Δt_sv,now − Δt_sv,prev) (the ambiguity, constant
// while locked, cancels; the atmosphere's change over an epoch is neglected), m. Differences over more than
// kMaxPhaseInterval end the chain.
constexpr double kMaxPhaseInterval = 2.0;  // s
double PhaseRangeChange(const RawSatellite& now, const RawSatellite& prev);
// A cycle slip between the epochs dt apart: lost lock, or a phase change the mean of the two Dopplers does
// not explain (beyond 5 σ of their difference over dt, plus 5 cm).
bool PhaseSlipped(const RawSatellite& now, const RawSatellite& prev, double dt);
// An epoch's satellites with a phase, by name ("G05"): what the next epoch differences against.
std::map<std::string, RawSatellite> PhasesByName(const std::vector<RawSatellite>& sats);
// The (now, previous) pairs of the satellites with a phase in both epochs, dt apart, that did not slip;
// *slips counts those that did.
using PhasePair = std::pair<const RawSatellite*, const RawSatellite*>;
std::vector<PhasePair> UnbrokenPhases(const std::vector<RawSatellite>& now,
                                      const std::map<std::string, RawSatellite>& prev, double dt, uint64_t* slips);

// Rows of residuals (predicted − measured), each in a nuisance group (its clock: the system for ranges,
// one group for range rates) with its variance; H: their Jacobian (rows × state dimension).
struct NuisanceRows {
  VecX r;
  MatX H;
  VecX variance;
  std::vector<int> group;
};

// Baarda's data snooping with the state's covariance P: the clock of each group estimated by generalised
// least squares from the rows, w_i = e_i/√(Q_e)_ii on the clock-free residuals e, the row of the largest
// |w| beyond w_max removed and the rest tested again. Returns the rows kept (indices into rows), in order.
// A group of one row says nothing (its clock absorbs it) and is kept untested.
std::vector<int> ScreenSatellites(const NuisanceRows& rows, const MatX& P, double w_max);
// Whether a screening kept most of what it was offered. Data snooping assumes a few outliers among many:
// when it removes more satellites than it keeps, the state, not those satellites, is wrong, and the epoch's
// rows are rejected whole (a lost estimate is then not held by the few satellites that happen to agree
// with it, and the watchdog sees the rejections).
inline bool ScreeningKeptMost(size_t kept, size_t offered) { return 2 * kept >= offered; }

// The rows' differences within each group against the group's row of least variance (groups of one row
// drop out): r_d, H_d, and their noise R_d = D·diag(variance)·Dᵀ. *groups_used: the groups left.
void DifferenceByGroup(const NuisanceRows& rows, VecX* r_d, MatX* H_d, MatX* R_d, int* groups_used = nullptr);
// How many differences DifferenceByGroup makes of rows in these groups: the rows less their groups.
int DifferenceCount(const std::vector<int>& group);

// Rows over a 3-vector x (r_d + H_d·(x − x0), noise R_d; x0 where they were evaluated) as the one constraint
// they put on x: ‖S·(x − z)‖² equals their whitened squared norm up to a constant. S (3×3) is the square root
// of the information H_dᵀ·R_d⁻¹·H_d, with a zero row for each direction the rows do not see (eigenvalue below
// 1e-9 of the largest: two satellites of one system see one), z their least-squares x with no change from
// x0 in those directions; rank: S's nonzero rows. Exact for rows linear in x: a pseudorange's line of sight
// moves by |δx|/ρ, so a metre off x0 costs 10⁻⁸ m.
struct LinearConstraint3 {
  Vec3 z = Vec3::Zero();
  Mat3 sqrt_info = Mat3::Zero();
  int rank = 0;
};
LinearConstraint3 CompressRows(const VecX& r_d, const MatX& H_d, const MatX& R_d, const Vec3& x0);

}  // namespace gins
