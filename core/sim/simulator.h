// Seeded, reproducible vehicle simulator: `gins simulate` writes its output to files (Simulate), and the
// end-to-end tests run the same drive in memory (Simulator).
//
// World: the local ENU frame w at sim.origin, fixed to the Earth (core/conventions.h). The vehicle drives in w (its
// roads are the tangent plane at the origin tilted by the grades, so far from the origin they climb by
// d²/2R: 2 m at 5 km); geodetic output (GNSS fixes, truth.csv) maps w through LocalEnuFrame(origin), the same
// map gins uses to read it. Two Earth models (sim.earth_rotation):
//   flat (false): no Earth rotation, gravity g_w = (0, 0, −NormalGravity(origin)) everywhere, as the flat
//     estimators assume; attitudes, velocities and headings are written as they are in w;
//   rotating (true): w turns with the Earth at ω_ie^w = Ω(0, cos φ0, sin φ0) (core/earth.h), gravity is the
//     exact WGS84 normal gravity with its centrifugal part at the vehicle's position, g_w(p_wb)
//     (NormalGravityWorld: the plumb line leans by distance / R away from the origin), and what a receiver
//     or a truth file gives in the local ENU frame l at its point (truth attitude and velocity, heading from
//     true north, GNSS velocity) is rotated there by R_w_l(p)ᵀ = LocalEnuFrame::RotationFromLocalEnu(p)ᵀ.
//
// Vehicle: body b = IMU frame FLU, R_wb = Rz(yaw)·Ry(−pitch) (roll zero, pitch = road grade, nose up
// positive), no side slip: v_w = ±speed·R_wb·e_x (− in a reverse segment: the body faces forward while the
// vehicle backs up), p_wb(0) = 0, yaw(0) = sim.initial_yaw, at rest at t = 0.
// Each segment commands an acceleration of the speed (forward in a forward segment, backwards in reverse)
// and a yaw rate, reached from the previous segment's values (zero before the first) by a cosine ramp over
// the first min(1 s, duration) of the segment, and a grade, reached by a cosine ramp over the whole
// segment. ω_b and a_w are therefore continuous, with one exception: the speed never goes negative. When it
// reaches zero under a negative acceleration the vehicle stops (a_w drops to zero, as when a car comes to
// rest) and stays stopped until the commanded acceleration turns positive. The yaw rate is applied as
// given, also at standstill (turning in place). The gear changes only at a standstill: a segment whose
// `reverse` differs from the previous segment's must start with the vehicle stopped.
// Yaw, pitch and speed are closed-form; the position integrates the velocity by Gauss–Legendre quadrature
// between knots placed at every break of smoothness, so the truth is exact to round-off and independent
// of gins's IMU kernel.
//
// Sensors (docs/formats.md §2.7 IMU model, §3 log format). Time stamps are start_time + k/rate, k = 0, 1, ... (wheel
// from k = 1: pulses count over (t − Δt, t]); records in time order, ties IMU, ODOM, GNSS, GVEL.
//   IMU   flat:     ω̃ = ω_b + bg + ηg,              ã = R_wbᵀ(a_w − g_w) + ba + ηa;
//         rotating: ω̃ = ω_b + R_wbᵀω_ie^w + bg + ηg, ã = R_wbᵀ(a_w + 2ω_ie^w×v_w − g_w(p_wb)) + ba + ηa;
//         sampled at the time stamp; η white with σ = density·√rate; biases = turn-on N(0, σ) per axis +
//         random walk (σ_rw·√dt per sample).
//   GNSS  antenna p_wb + R_wb·lever_b + e_k; e_k per axis white N(0, σ_enu), or with
//         gnss_noise_correlation τ > 0 first-order Gauss–Markov: e_k = ρ·e_{k−1} + √(1−ρ²)·σ·n_k,
//         ρ = exp(−Δt/τ), Δt = 1/gnss_rate, e_0 = σ·n_0 (stationary), running through outages.
//         Heading = compass(yaw(R_wb·Rz(mount_yaw)) + N(0, σ_heading)), the yaw taken in w (flat) or in the
//         local ENU frame at the antenna (rotating: from true north there); flagged invalid (and written
//         as 0) with probability heading_invalid_fraction; no fix in [start, start + duration) of an outage
//         (elapsed seconds); with probability gnss_outlier_probability a fix is moved by
//         gnss_outlier_magnitude in a uniform horizontal direction. σ columns = sim.gnss_sigma_enu when
//         write_gnss_sigma.
//   GVEL  when any gnss_velocity_sigma > 0, with every fix: the antenna velocity v_w + R_wb·(ω_b × lever_b)
//         (in the local ENU frame at the antenna when rotating) + N(0, σ) per axis, σ columns always written.
//   ODOM  wheel speeds v ∓ ω_b.z·track/2 (left, right; v < 0 in reverse), measured as wheel_scale·v +
//         N(0, wheel_speed_noise) averaged over the interval, counted as pulses = distance·pulses_per_rev /
//         (2π·wheel_radius), rounded to whole (signed) pulses with the remainder carried to the next interval
//         (as an encoder counts). No noise while the vehicle neither rolls nor turns: parked, the encoders
//         count zero.
//   A rate of 0 turns GNSS or the wheels off.
// log_start: the drive is simulated from start_time, but records (and truth rows) before start_time +
// log_start are not returned, nor an encoder interval that straddles it: the log of a vehicle already on
// its way. The records that remain are those of the whole drive, bit for bit.
// Randomness: one std::mt19937_64 per random source (IMU bias, IMU noise, GNSS position, heading, heading
// validity, outliers, wheels, GNSS velocity), each seeded from a master mt19937_64(sim.seed), and a fixed
// number of draws per sample whatever the options; so changing one sensor's settings leaves the other draws
// unchanged. Normals are drawn by Box–Muller from the engine's raw bits, so the streams do not depend on the
// standard library's distribution implementations.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/conventions.h"
#include "core/geodesy.h"
#include "core/io/log_record.h"
#include "core/measurements.h"
#include "core/nav_state.h"
#include "core/sim/raw_gnss.h"
#include "core/sim/sim_random.h"

namespace gins {

// simulate.* (only `gins simulate` reads it)
struct SimSegment {
  double duration = 0.0;     // s
  double accel = 0.0;        // m/s², rate of change of the speed (forward, or backwards in reverse)
  double yaw_rate = 0.0;     // rad/s   (yaml: yaw_rate_deg_s)
  double grade = 0.0;        // rad, road pitch reached at the end of the segment (yaml: grade_deg)
  bool reverse = false;      // driven backwards, the body facing forward
};

struct SimOptions {
  unsigned seed = 1;
  double start_time = 1700000000.0;
  GeodeticPoint origin{31.5, 120.4, 10.0};
  double initial_yaw = 0.0;   // rad ENU (yaml: initial_heading_deg, compass)
  std::vector<SimSegment> segments;
  unsigned repeat = 1;        // the segment list is driven this many times in a row (long benchmark drives)
  double imu_rate = 100.0, gnss_rate = 1.0, wheel_rate = 10.0;
  // True sensor errors.
  double gyro_noise_density = 0.5 * kDegToRad / 60.0, acc_noise_density = 0.05 / 60.0;
  double gyro_bias_rw = 10.0 * kDegToRad / 3600.0 / 60.0, acc_bias_rw = 0.002 / 60.0;
  double gyro_turn_on_bias = 100.0 * kDegToRad / 3600.0, acc_turn_on_bias = 0.03;  // per-axis 1-σ
  Vec3 gnss_sigma_enu = Vec3(0.02, 0.02, 0.03);
  bool write_gnss_sigma = true;
  double heading_sigma = 0.2 * kDegToRad;
  double heading_invalid_fraction = 0.05;
  std::vector<std::pair<double, double>> gnss_outages;  // [start (s after start), duration]
  double gnss_outlier_probability = 0.0, gnss_outlier_magnitude = 20.0;  // m
  Vec3 lever_b = Vec3(-0.17, -0.20, 0.0);
  double mount_yaw = 12.06 * kDegToRad;
  double wheel_radius = 0.155, pulses_per_rev = 1024.0, wheel_scale = 0.99, wheel_speed_noise = 0.02;
  double track_width = 1.6;
  // The rear-axle centre in the body (IMU) frame, as wheel.lever_arm_m: the segments drive that point (the
  // wheels and the non-holonomic constraint are there), and the IMU sits at −wheel_lever_b from it, so it
  // slides sideways in turns when the arm is along x. Zero: the IMU on the axle.
  Vec3 wheel_lever_b = Vec3::Zero();
  // Physics and field-log set-ups (header comment).
  bool earth_rotation = true;               // the rotating Earth model; false: flat
  Vec3 gnss_velocity_sigma = Vec3::Zero();  // m/s per ENU axis; all zero: no GVEL records
  double gnss_noise_correlation = 0.0;      // s, τ of the GNSS position noise; 0: white
  double log_start = 0.0;                   // s after start_time before which nothing is logged
  RawGnssSimConfig raw_gnss;                // obs.rnx (core/sim/raw_gnss.h), off by default
};

// The true motion at one instant.
struct TruthState {
  double t = 0.0;               // absolute time (start_time + elapsed)
  Vec3 p_wb = Vec3::Zero();
  Vec3 v_w = Vec3::Zero();
  Quat q_wb = Quat::Identity();
  Vec3 omega_b = Vec3::Zero();  // angular rate of b relative to w, in b (rad/s)
  Vec3 a_w = Vec3::Zero();      // acceleration in w, gravity excluded (m/s²)
  double speed = 0.0;           // speed (m/s), ≥ 0: forward, or backwards when reverse
  bool reverse = false;         // in a reverse segment: v_w = −speed·R_wb·e_x

  NavState ToNavState() const;  // biases zero
};

// The exact trajectory defined by SimOptions (segments, initial_yaw, origin, start_time).
class TruthTrajectory {
 public:
  // Throws std::invalid_argument when the segments are empty, negative or not finite, or change gear while
  // the vehicle moves.
  explicit TruthTrajectory(const SimOptions& sim);

  double start_time() const { return start_time_; }
  double duration() const { return duration_; }
  double end_time() const { return start_time_ + duration_; }
  const Vec3& gravity_w() const { return g_w_; }  // the flat model's gravity
  const LocalEnuFrame& frame() const { return frame_; }

  // State at an absolute time / at an elapsed time (seconds since start_time), within [0, duration].
  // A unix time as a double resolves only ~2.4e-7 s, so At(record time) is off by up to that much (µm at
  // driving speeds); SimRecord::truth is evaluated at the exact sample time.
  TruthState At(double t) const { return AtElapsed(t - start_time_); }
  TruthState AtElapsed(double s) const;

  // ∫ v ds and ∫ ω_b.z ds over [s0, s1] (elapsed seconds), v the signed speed along e_x (negative in
  // reverse): the wheels' distances come from these.
  Vec2 IntegrateSpeedAndYawRate(double s0, double s1) const;

 private:
  // A control input: piecewise constant values joined by cosine ramps; value, rate and integral are exact.
  class Profile {
   public:
    void Add(double t0, double ramp, double value);  // in time order
    double Value(double s) const;
    double Rate(double s) const;
    double RateOfRate(double s) const;  // the second derivative
    double Integral(double s) const;  // ∫ from 0 to s
    std::vector<double> Breaks() const;

   private:
    struct Piece {
      double t0, ramp, from, to, integral0;
    };
    const Piece& Find(double s) const;
    std::vector<Piece> pieces_;
  };
  struct Gear {
    double t0;     // elapsed time the segment starts
    bool reverse;
  };
  struct SpeedPhase {
    double t0;    // elapsed time the phase starts
    bool moving;  // moving: speed = A(s) − A(t0) with A = ∫ accel; stopped: speed 0
    double a0;    // A(t0)
  };

  void ComputeSpeedPhases();
  // Throws unless every change of gear happens at a standstill. names[i]: the segment starting gears_[i].
  void CheckGearChanges(const std::vector<std::string>& names) const;
  bool Reverse(double s) const;
  const SpeedPhase& Phase(double s) const;
  double Speed(double s) const;
  double Yaw(double s) const { return initial_yaw_ + yaw_rate_.Integral(s); }
  Vec3 Velocity(double s) const;
  // Knot interval containing s (knots_[i] ≤ s < knots_[i+1], clamped to the valid range).
  size_t KnotIndex(double s) const;

  double start_time_ = 0.0;
  double duration_ = 0.0;
  Vec3 imu_from_axle_b_ = Vec3::Zero();  // −SimOptions::wheel_lever_b
  double initial_yaw_ = 0.0;
  Vec3 g_w_ = Vec3::Zero();
  LocalEnuFrame frame_;
  Profile accel_, yaw_rate_, grade_;
  std::vector<SpeedPhase> phases_;
  std::vector<Gear> gears_;    // one per segment of positive duration, in time order
  std::vector<double> knots_;  // elapsed times; every break of smoothness is a knot
  std::vector<Vec3> knot_p_;   // p_wb at the knots
};

// One simulated log record (line 0) with the truth at its time.
struct SimRecord : LogRecord {
  // Truth at t() with the true IMU biases of the latest IMU sample (exact for IMU records).
  NavState truth;
  bool gnss_outlier = false;  // this fix was displaced as an outlier
};

// The measurement stream of a drive, generated lazily in time order.
class Simulator {
 public:
  // Throws std::invalid_argument on invalid options (rates, σ, probabilities, segments, log_start).
  explicit Simulator(const SimOptions& sim);

  // Next record in time order (from start_time + log_start on); false at the end of the drive.
  bool Next(SimRecord* record);

  const TruthTrajectory& truth() const { return truth_; }
  const SimOptions& options() const { return sim_; }
  // ω_ie in w (rad/s): zero for the flat model.
  const Vec3& earth_rate_w() const { return earth_rate_w_; }
  // The model's gravity at p_w: constant (flat) or exact normal gravity (rotating).
  Vec3 GravityAt(const Vec3& p_w) const;
  // R_w_l at p_w: takes vectors in the local ENU frame at p_w into w. Identity for the flat model, whose
  // outputs are given in w.
  Mat3 LocalToWorld(const Vec3& p_w) const;

 private:
  using Rng = SimRng;  // core/sim/sim_random.h

  // The next record of the whole drive (before the log_start cut); *from: the elapsed time the record
  // starts measuring at (its time, or the start of an encoder interval).
  bool Generate(SimRecord* r, double* from);
  void MakeImu(SimRecord* r);
  void MakeWheel(SimRecord* r);
  // Draws the fix's noise; false (no record) inside an outage. Queues the fix's GVEL record, if any.
  bool MakeGnss(SimRecord* r);
  // The GNSS position error of the epoch just counted in i_gnss_, from its standard normals (white or
  // Gauss–Markov).
  Vec3 GnssError(const Vec3& normals);
  // Queues the GVEL record of the fix at elapsed s (truth x, true antenna position p_ant_w), all but its
  // truth.
  void MakeGnssVelocity(double s, const TruthState& x, const Vec3& p_ant_w, const Vec3& normals);
  void FillTruth(double elapsed, SimRecord* r) const;

  SimOptions sim_;
  TruthTrajectory truth_;
  Rng rng_imu_bias_, rng_imu_noise_, rng_gnss_, rng_heading_, rng_heading_valid_, rng_outlier_, rng_wheel_;
  Rng rng_gvel_;
  Vec3 earth_rate_w_ = Vec3::Zero();
  uint64_t n_imu_ = 0, n_gnss_ = 0, n_wheel_ = 0;  // samples in the drive per stream
  uint64_t i_imu_ = 0, i_gnss_ = 0, i_wheel_ = 1;  // next sample index per stream
  Vec3 bg_ = Vec3::Zero(), ba_ = Vec3::Zero();    // current true biases
  Vec2 pulse_carry_ = Vec2::Zero();               // sub-pulse remainders (left, right)
  Vec3 gnss_error_ = Vec3::Zero();                // the Gauss–Markov GNSS error of the last epoch
  bool gnss_velocity_pending_ = false;                     // pending_ holds the last fix's GVEL record
  SimRecord pending_;
  double pending_from_ = 0.0;
};

struct SimulationResult {
  RecordCounts records{};        // of log.txt
  uint64_t raw_gnss_epochs = 0;  // of obs.rnx, when simulate.raw_gnss_enabled
  double duration = 0.0;  // s, of the whole drive (from start_time, whatever log_start)
};

// Runs the drive and writes out_dir/log.txt (docs/formats.md §3, with a `# gins simulate seed=...` header) and
// out_dir/truth.csv (docs/formats.md §4, one row per IMU record; attitude and velocity in the local ENU frame at the
// row's point when rotating, in w when flat), and with raw_gnss.enabled out_dir/obs.rnx (core/sim/raw_gnss.h:
// RawGnssSimConfig). out_dir is created if missing. Each file is written under a
// temporary name and renamed into place when complete. Throws std::invalid_argument on invalid options and
// std::runtime_error on I/O failure.
SimulationResult Simulate(const SimOptions& sim, const std::string& out_dir);

}  // namespace gins
