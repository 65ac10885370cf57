// Simulator: the sensors of a simulated drive (core/sim/simulator.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/earth.h"
#include "core/sim/sim_internal.h"
#include "core/sim/simulator.h"

namespace gins {
namespace {

using sim_internal::FiniteNonNegative;
using sim_internal::kTimeTolerance;
using sim_internal::Require;

void ValidateSensors(const SimOptions& sim) {
  Require(std::isfinite(sim.imu_rate) && sim.imu_rate > 0.0, "imu_rate must be > 0");
  Require(FiniteNonNegative(sim.gnss_rate), "gnss_rate must be >= 0 (0 = off)");
  Require(FiniteNonNegative(sim.wheel_rate), "wheel_rate must be >= 0 (0 = off)");
  for (double v : {sim.gyro_noise_density, sim.acc_noise_density, sim.gyro_bias_rw, sim.acc_bias_rw,
                   sim.gyro_turn_on_bias, sim.acc_turn_on_bias, sim.heading_sigma, sim.gnss_outlier_magnitude,
                   sim.wheel_speed_noise, sim.gnss_sigma_enu.x(), sim.gnss_sigma_enu.y(), sim.gnss_sigma_enu.z()}) {
    Require(FiniteNonNegative(v), "noise levels and σ must be finite and >= 0");
  }
  Require(sim.heading_invalid_fraction >= 0.0 && sim.heading_invalid_fraction <= 1.0,
          "heading_invalid_fraction must be in [0, 1]");
  Require(sim.gnss_outlier_probability >= 0.0 && sim.gnss_outlier_probability <= 1.0,
          "gnss_outlier_probability must be in [0, 1]");
  Require(std::isfinite(sim.wheel_radius) && sim.wheel_radius > 0.0, "wheel_radius must be > 0");
  Require(std::isfinite(sim.pulses_per_rev) && sim.pulses_per_rev > 0.0, "pulses_per_rev must be > 0");
  Require(std::isfinite(sim.wheel_scale) && std::isfinite(sim.track_width), "wheel_scale, track_width must be finite");
  Require(sim.lever_b.allFinite() && std::isfinite(sim.mount_yaw), "lever_b, mount_yaw must be finite");
  for (const auto& [start, length] : sim.gnss_outages) {
    Require(std::isfinite(start) && FiniteNonNegative(length), "gnss_outages need finite [start, duration >= 0]");
  }
  Require(sim.gnss_velocity_sigma.allFinite() && sim.gnss_velocity_sigma.minCoeff() >= 0.0,
          "gnss_velocity_sigma must be finite and >= 0");
  Require(FiniteNonNegative(sim.gnss_noise_correlation), "gnss_noise_correlation must be finite and >= 0");
}

// Number of samples k = first..K with k/rate ≤ duration (round-off tolerant).
uint64_t LastIndex(double rate, double duration) {
  return static_cast<uint64_t>(std::floor(duration * rate + kTimeTolerance));
}

}  // namespace

Simulator::Simulator(const SimOptions& sim)
    : sim_(sim),
      truth_(sim),
      rng_imu_bias_(DerivedSeed(sim.seed, 0)),
      rng_imu_noise_(DerivedSeed(sim.seed, 1)),
      rng_gnss_(DerivedSeed(sim.seed, 2)),
      rng_heading_(DerivedSeed(sim.seed, 3)),
      rng_heading_valid_(DerivedSeed(sim.seed, 4)),
      rng_outlier_(DerivedSeed(sim.seed, 5)),
      rng_wheel_(DerivedSeed(sim.seed, 6)),
      rng_gvel_(DerivedSeed(sim.seed, 7)) {
  ValidateSensors(sim);
  const double d = truth_.duration();
  Require(FiniteNonNegative(sim.log_start) && sim.log_start < d, "log_start must be >= 0 and before the drive ends");
  if (sim.earth_rotation) earth_rate_w_ = EarthModel::Rotating(truth_.frame()).rate_w();
  n_imu_ = LastIndex(sim.imu_rate, d) + 1;
  n_gnss_ = sim.gnss_rate > 0.0 ? LastIndex(sim.gnss_rate, d) + 1 : 0;
  n_wheel_ = sim.wheel_rate > 0.0 ? LastIndex(sim.wheel_rate, d) + 1 : 1;  // indices 1..last
  bg_ = sim.gyro_turn_on_bias * rng_imu_bias_.Normal3();
  ba_ = sim.acc_turn_on_bias * rng_imu_bias_.Normal3();
}

bool Simulator::Next(SimRecord* record) {
  double from = 0.0;
  while (Generate(record, &from)) {
    if (from >= sim_.log_start - kTimeTolerance) return true;
  }
  return false;
}

Vec3 Simulator::GravityAt(const Vec3& p_w) const {
  return sim_.earth_rotation ? NormalGravityWorld(truth_.frame(), p_w) : truth_.gravity_w();
}

Mat3 Simulator::LocalToWorld(const Vec3& p_w) const {
  if (!sim_.earth_rotation) return Mat3::Identity();
  return truth_.frame().RotationFromLocalEnu(truth_.frame().ToGeodetic(p_w));
}

bool Simulator::Generate(SimRecord* record, double* from) {
  if (gnss_velocity_pending_) {  // right after its fix: a tie, and GVEL comes last
    gnss_velocity_pending_ = false;
    *record = pending_;
    *from = pending_from_;
    return true;
  }
  constexpr double kNever = std::numeric_limits<double>::infinity();
  for (;;) {
    // Elapsed times k/rate: equal rationals give equal doubles, so simultaneous samples tie exactly.
    const double t_imu = i_imu_ < n_imu_ ? static_cast<double>(i_imu_) / sim_.imu_rate : kNever;
    const double t_wheel = i_wheel_ < n_wheel_ ? static_cast<double>(i_wheel_) / sim_.wheel_rate : kNever;
    const double t_gnss = i_gnss_ < n_gnss_ ? static_cast<double>(i_gnss_) / sim_.gnss_rate : kNever;
    if (t_imu == kNever && t_wheel == kNever && t_gnss == kNever) return false;
    *record = SimRecord();
    if (t_imu <= t_wheel && t_imu <= t_gnss) {
      *from = t_imu;
      MakeImu(record);
      return true;
    }
    if (t_wheel <= t_gnss) {
      *from = static_cast<double>(i_wheel_ - 1) / sim_.wheel_rate;  // the counting interval's start
      MakeWheel(record);
      return true;
    }
    *from = t_gnss;
    if (MakeGnss(record)) return true;
  }
}

void Simulator::FillTruth(double elapsed, SimRecord* r) const {
  r->truth = truth_.AtElapsed(std::min(elapsed, truth_.duration())).ToNavState();
  r->truth.bg = bg_;
  r->truth.ba = ba_;
}

void Simulator::MakeImu(SimRecord* r) {
  const double rate = sim_.imu_rate;
  const double s = static_cast<double>(i_imu_) / rate;
  if (i_imu_ > 0) {
    const double sqrt_dt = std::sqrt(1.0 / rate);
    bg_ += sim_.gyro_bias_rw * sqrt_dt * rng_imu_bias_.Normal3();
    ba_ += sim_.acc_bias_rw * sqrt_dt * rng_imu_bias_.Normal3();
  }
  const TruthState x = truth_.AtElapsed(std::min(s, truth_.duration()));
  const Vec3 noise_g = sim_.gyro_noise_density * std::sqrt(rate) * rng_imu_noise_.Normal3();
  const Vec3 noise_a = sim_.acc_noise_density * std::sqrt(rate) * rng_imu_noise_.Normal3();
  ImuSample& imu = r->data.emplace<ImuSample>();
  imu.t = sim_.start_time + s;
  if (sim_.earth_rotation) {
    // The gyro measures the rotation against inertial space; the accelerometer, the specific force in the
    // inertial frame: a_w plus Coriolis, minus the gravity (with its centrifugal part) at the vehicle.
    const Quat q_bw = x.q_wb.conjugate();
    imu.gyro = x.omega_b + q_bw * earth_rate_w_ + bg_ + noise_g;
    imu.acc = q_bw * (x.a_w + 2.0 * earth_rate_w_.cross(x.v_w) - GravityAt(x.p_wb)) + ba_ + noise_a;
  } else {
    imu.gyro = x.omega_b + bg_ + noise_g;
    imu.acc = x.q_wb.conjugate() * (x.a_w - truth_.gravity_w()) + ba_ + noise_a;
  }
  r->truth = x.ToNavState();
  r->truth.bg = bg_;
  r->truth.ba = ba_;
  ++i_imu_;
}

void Simulator::MakeWheel(SimRecord* r) {
  const double dt = 1.0 / sim_.wheel_rate;
  const double s1 = std::min(static_cast<double>(i_wheel_) / sim_.wheel_rate, truth_.duration());
  const double s0 = static_cast<double>(i_wheel_ - 1) / sim_.wheel_rate;
  // Distances of the wheel contact points: body speed ∓ half the track times the body yaw rate.
  const Vec2 integral = truth_.IntegrateSpeedAndYawRate(s0, s1);
  const double half_turn = 0.5 * sim_.track_width * integral.y();
  // A wheel that does not turn counts no pulses: the speed noise (slip, tyre) exists only in motion.
  const bool rolling = std::abs(integral.x()) > 0.0 || std::abs(half_turn) > 0.0;
  const Vec2 noise = (rolling ? sim_.wheel_speed_noise : 0.0) * Vec2(rng_wheel_.Normal(), rng_wheel_.Normal());
  const Vec2 distance = sim_.wheel_scale * Vec2(integral.x() - half_turn, integral.x() + half_turn) + noise * dt;
  const Vec2 counts = distance * sim_.pulses_per_rev / (2.0 * kPi * sim_.wheel_radius) + pulse_carry_;
  const Vec2 pulses(std::round(counts.x()), std::round(counts.y()));
  pulse_carry_ = counts - pulses;
  WheelRecord& wheel = r->data.emplace<WheelRecord>();
  wheel.t = sim_.start_time + static_cast<double>(i_wheel_) / sim_.wheel_rate;
  wheel.left_pulses = pulses.x();
  wheel.right_pulses = pulses.y();
  FillTruth(s1, r);
  ++i_wheel_;
}

bool Simulator::MakeGnss(SimRecord* r) {
  const double s = static_cast<double>(i_gnss_) / sim_.gnss_rate;
  ++i_gnss_;
  // Every fix draws the same numbers, used or not, so outages and probabilities shift nothing else.
  const Vec3 noise = rng_gnss_.Normal3();
  const double heading_noise = rng_heading_.Normal();
  const bool heading_valid = rng_heading_valid_.Uniform() >= sim_.heading_invalid_fraction;
  const bool outlier = rng_outlier_.Uniform() < sim_.gnss_outlier_probability;
  const double outlier_dir = 2.0 * kPi * rng_outlier_.Uniform();
  const Vec3 gvel_noise = rng_gvel_.Normal3();
  const Vec3 error = GnssError(noise);  // the error process runs through outages
  for (const auto& [start, length] : sim_.gnss_outages) {
    if (s >= start && s < start + length) return false;
  }

  const TruthState x = truth_.AtElapsed(std::min(s, truth_.duration()));
  const Vec3 p_ant_true_w = x.p_wb + x.q_wb * sim_.lever_b;
  Vec3 p_ant_w = p_ant_true_w + error;
  if (outlier) p_ant_w += sim_.gnss_outlier_magnitude * Vec3(std::cos(outlier_dir), std::sin(outlier_dir), 0.0);
  const GeodeticPoint geo = truth_.frame().ToGeodetic(p_ant_w);
  const Vec3 x_G_w = x.q_wb * Vec3(std::cos(sim_.mount_yaw), std::sin(sim_.mount_yaw), 0.0);
  double yaw_G = 0.0;
  if (sim_.earth_rotation) {
    // The receiver's heading is from true north at the antenna: the baseline's yaw in the local ENU frame.
    const Vec3 x_G_l = LocalToWorld(p_ant_true_w).transpose() * x_G_w;
    yaw_G = std::atan2(x_G_l.y(), x_G_l.x()) + sim_.heading_sigma * heading_noise;
  } else {
    yaw_G = std::atan2(x_G_w.y(), x_G_w.x()) + sim_.heading_sigma * heading_noise;
  }

  GnssRecord& fix = r->data.emplace<GnssRecord>();
  fix.t = sim_.start_time + s;
  fix.lat_deg = geo.lat_deg;
  fix.lon_deg = geo.lon_deg;
  fix.alt_m = geo.alt_m;
  fix.heading_valid = heading_valid;
  fix.heading_deg = heading_valid ? EnuYawToCompassDeg(yaw_G) : 0.0;
  fix.has_sigma = sim_.write_gnss_sigma;
  if (sim_.write_gnss_sigma) fix.sigma_enu = sim_.gnss_sigma_enu;
  r->gnss_outlier = outlier;
  FillTruth(s, r);
  if ((sim_.gnss_velocity_sigma.array() > 0.0).any()) {
    MakeGnssVelocity(s, x, p_ant_true_w, gvel_noise);
    pending_.truth = r->truth;
  }
  return true;
}

Vec3 Simulator::GnssError(const Vec3& normals) {
  const Vec3 white = sim_.gnss_sigma_enu.cwiseProduct(normals);
  const double tau = sim_.gnss_noise_correlation;
  if (tau == 0.0) return white;
  // First-order Gauss–Markov, started at its stationary distribution (the first epoch's error is white).
  if (i_gnss_ == 1) {
    gnss_error_ = white;
  } else {
    const double rho = std::exp(-1.0 / (sim_.gnss_rate * tau));
    gnss_error_ = rho * gnss_error_ + std::sqrt(1.0 - rho * rho) * white;
  }
  return gnss_error_;
}

void Simulator::MakeGnssVelocity(double s, const TruthState& x, const Vec3& p_ant_w, const Vec3& normals) {
  // Doppler measures the antenna's velocity against the Earth, given in the local ENU frame at the antenna.
  const Vec3 v_ant_w = x.v_w + x.q_wb * x.omega_b.cross(sim_.lever_b);
  pending_ = SimRecord();
  GnssVelocityRecord& velocity = pending_.data.emplace<GnssVelocityRecord>();
  velocity.t = sim_.start_time + s;
  velocity.v_enu = LocalToWorld(p_ant_w).transpose() * v_ant_w + sim_.gnss_velocity_sigma.cwiseProduct(normals);
  velocity.has_sigma = true;
  velocity.sigma_enu = sim_.gnss_velocity_sigma;
  pending_from_ = s;
  gnss_velocity_pending_ = true;
}

}  // namespace gins
