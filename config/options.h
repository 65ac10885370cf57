// Typed options: every setting gins reads, in SI units, with in-class defaults equal to
// config/default.yaml. The YAML loader (config/config_loader.h) is the only code that reads YAML; it
// converts the users' units (named in each key) to SI once, validates ranges and rejects unknown keys.
// Comments give the YAML key path and its unit.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/conventions.h"
#include "core/geodesy.h"

namespace gins {

enum class InputErrorPolicy { kSkip, kStop };

// input.*
struct InputOptions {
  InputErrorPolicy on_error = InputErrorPolicy::kSkip;  // input.on_error: skip | stop
  int max_errors = 1000;             // input.max_errors: give up after this many skipped lines (skip policy)
  int max_line_length = 4096;        // input.max_line_length: characters; longer lines are damage
  double max_time_jump = 60.0;       // input.max_time_jump_s: a record this far ahead of the newest time is
                                     // damage (time_jump); 0 = no limit
};

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

// gnss.*
struct GnssOptions {
  Vec3 lever_b = Vec3(-0.17, -0.20, 0.0);  // gnss.lever_arm_m: antenna position in b
  double mount_yaw = 12.06 * kDegToRad;    // gnss.mount_yaw_deg: yaw of the antenna baseline frame G in b
  Vec3 sigma_enu = Vec3(0.05, 0.05, 0.10);  // gnss.sigma_m [e, n, u]: used when a fix carries no σ
  double min_sigma = 0.005;                // gnss.min_sigma_m: floor for logged σ (a zero σ is not trusted)
  double heading_sigma = 0.5 * kDegToRad;   // gnss.heading_sigma_deg
  bool use_heading = true;                 // gnss.use_heading
  double gate_probability = 0.9999;        // gnss.gate_probability: χ² gate on the innovation (0 = off)
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
};

// wheel.*
struct WheelOptions {
  bool enabled = true;              // wheel.enabled
  double radius = 0.155;            // wheel.radius_m
  double pulses_per_rev = 1024.0;   // wheel.pulses_per_rev
  double interval = 0.1;            // wheel.interval_s: pulse counting interval
  double speed_sigma = 0.1;         // wheel.speed_sigma_m_s
  double gate_probability = 0.9999; // wheel.gate_probability
  double scale_sigma = 0.05;        // wheel.scale_sigma: prior 1-σ of the odometer scale (initial value 1)
  double scale_rw = 1e-4;           // wheel.scale_rw_per_sqrt_s: random walk of the scale
  bool estimate_scale = true;       // wheel.estimate_scale
  bool nonholonomic = false;        // wheel.nonholonomic: zero lateral/vertical body speed
  double nhc_sigma = 0.1;           // wheel.nhc_sigma_m_s
};

// gravity.*
struct GravityOptions {
  bool use_normal_gravity = true;   // gravity.model: normal (WGS84 at the origin) | fixed
  double magnitude = kStandardGravity;  // gravity.magnitude_m_s2 (model fixed)
};

// init.*
struct InitOptions {
  double static_duration = 2.0;     // init.static_duration_s: standstill needed before starting
  double max_gyro_std = 0.5 * kDegToRad;  // init.max_gyro_std_deg_s: "IMU quiet" thresholds
  double max_acc_std = 0.1;         // init.max_acc_std_m_s2
  double max_wait = 300.0;          // init.max_wait_s: give up if no standstill was found by then
  bool wait_for_heading = true;     // init.wait_for_heading: take yaw from the first valid heading
  double sigma_pos = 0.1;           // init.sigma_pos_m   (added to the first fix's σ)
  double sigma_vel = 0.05;          // init.sigma_vel_m_s
  double sigma_roll_pitch = 0.5 * kDegToRad;  // init.sigma_roll_pitch_deg
  double sigma_yaw = 2.0 * kDegToRad;         // init.sigma_yaw_deg (no heading: 180)
};

// eskf.*
struct EskfOptions {
  bool estimate_gravity = true;     // eskf.estimate_gravity: δg in the error state
  double gravity_sigma = 0.01;      // eskf.gravity_sigma_m_s2 initial 1-σ per axis
};

// smoother.*
struct SmootherOptions {
  int window_size = 10;             // smoother.window_size: keyframes in the window
  double max_keyframe_interval = 1.0;  // smoother.max_keyframe_interval_s
  double min_keyframe_interval = 0.5;  // smoother.min_keyframe_interval_s: faster GNSS is decimated
  std::string linear_solver = "sparse_normal_cholesky";  // smoother.linear_solver: sparse_normal_cholesky | dense_schur
  int max_iterations = 10;          // smoother.max_iterations
  double function_tolerance = 1e-6;  // smoother.function_tolerance: stop when |Δcost|/cost falls below
  int num_threads = 1;              // smoother.num_threads
  double gnss_loss_scale = 3.0;     // smoother.gnss_loss_scale: Cauchy loss scale on whitened residuals
  double bias_reintegrate_threshold = 1e-3;  // smoother.bias_reintegrate_threshold (norm of δb)
};

// standstill.*: zero-velocity and zero-rotation updates while the vehicle stands (core/standstill_detector.h).
struct StandstillOptions {
  bool enabled = true;                    // standstill.enabled
  double window = 1.0;                    // standstill.window_s: IMU samples judged together
  double max_gyro_std = 0.5 * kDegToRad;  // standstill.max_gyro_std_deg_s: "IMU quiet" thresholds
  double max_acc_std = 0.1;               // standstill.max_acc_std_m_s2
  double velocity_sigma = 0.01;           // standstill.velocity_sigma_m_s: 1-σ of the zero velocity
  double max_speed = 0.5;                 // standstill.max_speed_m_s: ignore a detection above this speed
};

// watchdog.*: divergence detection and re-initialisation from GNSS.
struct WatchdogOptions {
  bool enabled = true;                // watchdog.enabled
  double max_reject = 15.0;           // watchdog.max_reject_s: every GNSS fix rejected for this long
  double max_position_sigma = 100.0;  // watchdog.max_position_sigma_m: position 1-σ that counts as exploded
};

// simulate.* (only `gins simulate` reads it)
struct SimSegment {
  double duration = 0.0;     // s
  double accel = 0.0;        // m/s², forward
  double yaw_rate = 0.0;     // rad/s   (yaml: yaw_rate_deg_s)
  double grade = 0.0;        // rad, road pitch reached at the end of the segment (yaml: grade_deg)
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
};

struct Options {
  InputOptions input;
  ImuOptions imu;
  GnssOptions gnss;
  WheelOptions wheel;
  GravityOptions gravity;
  InitOptions init;
  EskfOptions eskf;
  SmootherOptions smoother;
  StandstillOptions standstill;
  WatchdogOptions watchdog;
  SimOptions simulate;
};

}  // namespace gins
