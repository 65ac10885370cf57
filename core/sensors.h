// The sensors' descriptions every estimator and the initialisation share: IMU noise model and axes, GNSS
// antenna geometry and noise, wheel encoders, gravity model. In SI units with in-class defaults equal to
// config/default.yaml; config/ fills them from YAML (the comments give each key path and unit).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/conventions.h"
#include "core/geodesy.h"
#include "core/measurement_modules.h"

namespace gins {

// imu.*
struct ImuOptions {
  // imu.axes: FLU | FRD | RFU | matrix (3x3 row-major list) mapping logged axes into the body FLU frame.
  Mat3 R_b_imu = Mat3::Identity();
  double gyro_noise_density = 0.8 * kDegToRad / 60.0;   // imu.gyro_noise_deg_sqrt_h → rad/s/√Hz
  double acc_noise_density = 0.08 / 60.0;                // imu.acc_noise_m_s_sqrt_h → m/s²/√Hz
  double gyro_bias_rw = 60.0 * kDegToRad / 3600.0 / 60.0;  // imu.gyro_bias_rw_deg_h_sqrt_h → rad/s/√s
  double acc_bias_rw = 0.01 / 60.0;                      // imu.acc_bias_rw_m_s2_sqrt_h → m/s²/√s
  double init_gyro_bias_sigma = 300.0 * kDegToRad / 3600.0;  // imu.init_gyro_bias_sigma_deg_h → rad/s
  double init_acc_bias_sigma = 0.1;                      // imu.init_acc_bias_sigma_m_s2 → m/s²
  double max_gap = 0.5;                // imu.max_gap_s: a longer IMU gap is not integrated across
  double max_gyro = 35.0;              // imu.max_gyro_rad_s: larger readings are absurd (damage)
  double max_acc = 200.0;              // imu.max_acc_m_s2
};

// raw_gnss.*: raw observations (RINEX 3) for the tightly coupled updates (core/gnss_raw.h).
struct GnssRawOptions {
  std::string obs_file;  // raw_gnss.obs_file: RINEX 3 observation file ("": none); `gins run --obs`
  std::string nav_file;  // raw_gnss.nav_file: RINEX 3 navigation file; `gins run --nav`
  double elevation_mask = 15.0 * kDegToRad;  // raw_gnss.elevation_mask_deg
  // raw_gnss.ionosphere: auto (the ionosphere-free combination where a satellite has two codes, else
  // Klobuchar where the navigation file gives GPSA/GPSB, else none) | klobuchar | iono_free | none.
  enum class Ionosphere { kAuto, kKlobuchar, kIonosphereFree, kNone };
  Ionosphere ionosphere = Ionosphere::kAuto;
  double code_sigma = 0.3;     // raw_gnss.code_sigma_m: pseudorange σ² = a² + b²/sin²(el), a = b = this
  double doppler_sigma = 0.1;  // raw_gnss.doppler_sigma_m_s: range-rate σ = this·(1 + 1/sin el)
  bool use_doppler = true;      // raw_gnss.use_doppler
  bool use_phase = true;        // raw_gnss.use_phase: time-differenced carrier phase between epochs
  double phase_sigma = 0.003;   // raw_gnss.phase_sigma_m: its σ = this·(1 + 1/sin el)
  // raw_gnss.init_max_attitude_sigma_deg: the initialisation's acceptance when raw epochs initialise (the
  // larger of it and init.max_attitude_sigma_deg).
  double init_max_attitude_sigma = 10.0 * kDegToRad;
};

// gnss.*
struct GnssOptions {
  Vec3 lever_b = Vec3(-0.17, -0.20, 0.0);  // gnss.lever_arm_m: antenna position in b
  double mount_yaw = 12.06 * kDegToRad;    // gnss.mount_yaw_deg: yaw of the antenna baseline frame G in b
  Vec3 sigma_enu = Vec3(0.05, 0.05, 0.10);  // gnss.sigma_m [e, n, u]: used when a fix carries no σ
  double min_sigma = 0.005;                // gnss.min_sigma_m: floor for logged σ (a zero σ is not trusted)
  // gnss.time_offset_s: the GNSS records (fixes, headings, velocities) are stamped this much after the IMU
  // time at which they were measured (a receiver's latency into the logger). A number: gins takes t − offset,
  // and a raw epoch's GPS time less it (the log's clock behind GPS time). `estimate` (estimate_time_offset):
  // the ESKF (solver/eskf.h) and the smoothers (a keyframe block, solver/keyframe.h) estimate the rest as a
  // state, from 0 with 1-σ time_offset_sigma and a random walk time_offset_rw (from the records; raw epochs
  // hold it at 0).
  double time_offset = 0.0;
  bool estimate_time_offset = true;
  double time_offset_sigma = 0.1;  // gnss.time_offset_sigma_s
  double time_offset_rw = 1e-4;    // gnss.time_offset_rw_s_sqrt_s → s/√s
  // gnss.error_correlation_s: correlation time τ of the fixes' errors; each σ is inflated by
  // √((1+ρ)/(1−ρ)), ρ = exp(−Δt/τ), Δt the spacing of the fixes (core/gnss_noise.h). 0: independent fixes.
  double error_correlation = 0.0;
  double heading_sigma = 0.5 * kDegToRad;   // gnss.heading_sigma_deg
  bool use_heading = true;                 // gnss.use_heading
  double gate_probability = 0.9999;        // gnss.gate_probability: χ² gate on the innovation (0 = off)
  bool use_velocity = true;                // gnss.use_velocity: use GVEL records (Doppler velocity)
  Vec3 velocity_sigma_enu = Vec3(0.1, 0.1, 0.2);  // gnss.velocity_sigma_m_s: for a GVEL record without σ
  double min_velocity_sigma = 0.01;        // gnss.min_velocity_sigma_m_s: floor for a logged velocity σ
  std::optional<GeodeticPoint> origin;     // gnss.origin: [lat_deg, lon_deg, alt_m]; absent = first fix
  // Simulated GNSS outages (fixes in a window are dropped once initialised), times in s after the log's
  // first record; each window is [start, start + duration).
  std::vector<std::pair<double, double>> outages;  // gnss.outages_s: [[start_s, duration_s], ...]
  struct PeriodicOutages {
    double first_start = 0.0;  // s after the first record
    double duration = 0.0;     // s; 0 = none
    double period = 0.0;       // s, start to start
  };
  PeriodicOutages periodic_outages;  // gnss.periodic_outages_s: [first_start_s, duration_s, period_s] or []
  GnssRawOptions raw;                // raw_gnss (its own section)
};

// wheel.*
struct WheelOptions {
  bool enabled = true;              // wheel.enabled
  double radius = 0.155;            // wheel.radius_m
  double pulses_per_rev = 1024.0;   // wheel.pulses_per_rev
  double interval = 0.1;            // wheel.interval_s: nominal pulse counting interval (records' own
                                    // spacing is used within ±50 % of it)
  double speed_sigma = 0.1;         // wheel.speed_sigma_m_s
  double gate_probability = 0.9999; // wheel.gate_probability
  double scale_sigma = 0.05;        // wheel.scale_sigma: prior 1-σ of the odometer scale (initial value 1)
  double scale_rw = 1e-4;           // wheel.scale_rw_per_sqrt_s: random walk of the scale
  bool estimate_scale = true;       // wheel.estimate_scale
  Vec3 lever_b = Vec3::Zero();      // wheel.lever_arm_m: the rear-axle centre in b (where the NHC holds)
  double track = 0.0;               // wheel.track_m: left-right wheel distance; 0 = no yaw-rate aid
};

// vehicle.*: constraints of the vehicle itself, whatever its sensors.
struct VehicleOptions {
  bool nonholonomic = true;         // vehicle.nonholonomic: no sideways or vertical speed at the rear axle
  double nhc_sigma = 0.1;           // vehicle.nhc_sigma_m_s: 1-σ of that speed
  double nhc_rate = 10.0;           // vehicle.nhc_rate_hz: how often the ESKF applies it
};

// gravity.*
struct GravityOptions {
  // gravity.earth_rotation: the Earth turns under w (Earth rate, Coriolis, normal gravity by position:
  // core/earth.h); false = the flat, non-rotating model.
  bool earth_rotation = true;
  bool use_normal_gravity = true;   // gravity.model: normal (WGS84) | fixed
  double magnitude = kStandardGravity;  // gravity.magnitude_m_s2 (model fixed)
};

// The sensors of a log, as a group.
struct SensorOptions {
  ImuOptions imu;
  GnssOptions gnss;
  WheelOptions wheel;
  VehicleOptions vehicle;
  GravityOptions gravity;
  // Each measurement module's section (core/measurement_modules.h), by its type: std::get<Mod::Options>.
  MeasurementModules::Options modules;
};

}  // namespace gins
