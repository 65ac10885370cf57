// Every config key, declared once: its name (with the unit suffix the user writes), the option it sets, its
// unit and its allowed values. Key names and units here are the contract documented in config/default.yaml
// (tests/config/config_keys_test.cc keeps the two in step).
//
// Each kXxxKeys below is a generic lambda run with one of three visitors, which makes it
//   YamlReader (yaml_reader.h)  read, validate and convert the file's values: LoadOptions;
//   YamlWriter (yaml_writer.h)  write the options in the users' units: OptionsToYaml;
//   KeyLister  (key_lister.h)   list the key paths: ConfigKeys.
// A visitor has one method per kind of value, each taking the key first:
//   Number(key, double&, Unit, Check[, Presence])   Integer(key, int-type&, min[, max])   Boolean(key, bool&)
//   String(key, std::string&)
//   Choice(key, T&, Choices<T>)   Vector3(key, Vec3&, what, Check)   Axes(key, Mat3&)
//   Origin(key, GeodeticPoint& or optional<GeodeticPoint>&)   Outages(key, [[start, duration]]&)
//   PeriodicOutages(key, GnssOptions::PeriodicOutages&)
//   Section(key, struct&, keys)   List(key, item noun, vector&, keys of an item)
// The reader checks keys in declaration order (the first bad one is reported) and the writer writes them
// in it, so the order here is the order of the echoed file.
//
// Internal to config/.
#pragma once

#include <limits>

#include "config/key_spec.h"
#include "config/options.h"

namespace gins::config_internal {

inline constexpr auto kInputKeys = [](auto& v, InputOptions& o) {
  v.Choice("on_error", o.on_error,
           Choices<InputErrorPolicy>{{"skip", InputErrorPolicy::kSkip}, {"stop", InputErrorPolicy::kStop}});
  v.Integer("max_errors", o.max_errors, 0);
  v.Integer("max_line_length", o.max_line_length, 1);
  v.Number("max_time_jump_s", o.max_time_jump, kNoUnit, NonNegative());
  v.Number("reorder_window_s", o.reorder_window, kNoUnit, Within(0.0, 60.0));
  v.Boolean("regularize_stamps", o.regularize_stamps);
};

inline constexpr auto kImuKeys = [](auto& v, ImuOptions& o) {
  v.Axes("axes", o.R_b_imu);
  v.Number("gyro_noise_deg_sqrt_h", o.gyro_noise_density, kDegPerSqrtH, Positive());
  v.Number("acc_noise_m_s_sqrt_h", o.acc_noise_density, kPerSqrtH, Positive());
  v.Number("gyro_bias_rw_deg_h_sqrt_h", o.gyro_bias_rw, kDegPerHPerSqrtH, Positive());
  v.Number("acc_bias_rw_m_s2_sqrt_h", o.acc_bias_rw, kPerSqrtH, Positive());
  v.Number("init_gyro_bias_sigma_deg_h", o.init_gyro_bias_sigma, kDegPerH, Positive());
  v.Number("init_acc_bias_sigma_m_s2", o.init_acc_bias_sigma, kNoUnit, Positive());
  v.Number("max_gap_s", o.max_gap, kNoUnit, Positive());
  v.Number("max_gyro_rad_s", o.max_gyro, kNoUnit, Positive());
  v.Number("max_acc_m_s2", o.max_acc, kNoUnit, Positive());
};

// A lever arm typed in millimetres is the likely mistake behind an arm of more than 100 m.
constexpr Check kLeverCheck = Within(-100.0, 100.0);
constexpr const char* kLeverWhat = "[x, y, z] in the body frame (FLU)";

inline constexpr auto kGnssKeys = [](auto& v, GnssOptions& o) {
  v.Vector3("lever_arm_m", o.lever_b, kLeverWhat, kLeverCheck);
  v.Number("mount_yaw_deg", o.mount_yaw, kDeg, Within(-360.0, 360.0));
  v.Vector3("sigma_m", o.sigma_enu, "[east, north, up]", Positive());
  v.Number("min_sigma_m", o.min_sigma, kNoUnit, Positive());
  v.Number("error_correlation_s", o.error_correlation, kNoUnit, NonNegative());
  v.NumberOrWord("time_offset_s", o.time_offset, o.estimate_time_offset, "estimate", kNoUnit, Within(-5.0, 5.0));
  v.Number("time_offset_sigma_s", o.time_offset_sigma, kNoUnit, Within(1e-6, 1.0));
  v.Number("time_offset_rw_s_sqrt_s", o.time_offset_rw, kNoUnit, NonNegative());
  v.Number("heading_sigma_deg", o.heading_sigma, kDeg, Positive());
  v.Boolean("use_heading", o.use_heading);
  v.Number("gate_probability", o.gate_probability, kNoUnit, GateProbability());
  v.Boolean("use_velocity", o.use_velocity);
  v.Vector3("velocity_sigma_m_s", o.velocity_sigma_enu, "[east, north, up]", Positive());
  v.Number("min_velocity_sigma_m_s", o.min_velocity_sigma, kNoUnit, Positive());
  v.Origin("origin", o.origin);  // optional: null = the first usable fix
  v.Outages("outages_s", o.outages);
  v.PeriodicOutages("periodic_outages_s", o.periodic_outages);
};

inline constexpr auto kRawGnssInputKeys = [](auto& v, GnssRawOptions& o) {
  v.String("obs_file", o.obs_file);
  v.String("nav_file", o.nav_file);
  v.Number("elevation_mask_deg", o.elevation_mask, kDeg, Within(0.0, 60.0));
  using Iono = GnssRawOptions::Ionosphere;
  v.Choice("ionosphere", o.ionosphere,
           Choices<Iono>{{"auto", Iono::kAuto},
                         {"klobuchar", Iono::kKlobuchar},
                         {"iono_free", Iono::kIonosphereFree},
                         {"none", Iono::kNone}});
  v.Number("code_sigma_m", o.code_sigma, kNoUnit, Positive());
  v.Number("doppler_sigma_m_s", o.doppler_sigma, kNoUnit, Positive());
  v.Boolean("use_doppler", o.use_doppler);
  v.Boolean("use_phase", o.use_phase);
  v.Number("phase_sigma_m", o.phase_sigma, kNoUnit, Positive());
  v.Number("init_max_attitude_sigma_deg", o.init_max_attitude_sigma, kDeg, Within(0.01, 30.0));
};

inline constexpr auto kWheelKeys = [](auto& v, WheelOptions& o) {
  v.Boolean("enabled", o.enabled);
  v.Number("radius_m", o.radius, kNoUnit, Positive());
  v.Number("pulses_per_rev", o.pulses_per_rev, kNoUnit, Positive());
  v.Number("interval_s", o.interval, kNoUnit, Positive());
  v.Number("speed_sigma_m_s", o.speed_sigma, kNoUnit, Positive());
  v.Number("gate_probability", o.gate_probability, kNoUnit, GateProbability());
  v.Number("scale_sigma", o.scale_sigma, kNoUnit, Positive());
  v.Number("scale_rw_per_sqrt_s", o.scale_rw, kNoUnit, Positive());
  v.Boolean("estimate_scale", o.estimate_scale);
  v.Vector3("lever_arm_m", o.lever_b, kLeverWhat, kLeverCheck);
  v.Number("track_m", o.track, kNoUnit, Within(0.0, 100.0));
};

inline constexpr auto kVehicleKeys = [](auto& v, VehicleOptions& o) {
  v.Boolean("nonholonomic", o.nonholonomic);
  v.Number("nhc_sigma_m_s", o.nhc_sigma, kNoUnit, Positive());
  v.Number("nhc_rate_hz", o.nhc_rate, kNoUnit, Within(0.01, 1000.0));
};

inline constexpr auto kGravityKeys = [](auto& v, GravityOptions& o) {
  v.Boolean("earth_rotation", o.earth_rotation);
  v.Choice("model", o.use_normal_gravity, Choices<bool>{{"normal", true}, {"fixed", false}});
  // Earth's surface gravity spans 9.76-9.84 m/s²; anything far outside is a typo, not a place.
  v.Number("magnitude_m_s2", o.magnitude, kNoUnit, Within(9.7, 9.9));
};

inline constexpr auto kInitKeys = [](auto& v, InitOptions& o) {
  v.Number("static_duration_s", o.static_duration, kNoUnit, Positive());
  v.Number("max_wait_s", o.max_wait, kNoUnit, Positive());
  v.Boolean("wait_for_heading", o.wait_for_heading);
  v.Number("max_attitude_sigma_deg", o.max_attitude_sigma, kDeg, Within(0.01, 10.0));
};

inline constexpr auto kEskfKeys = [](auto& v, EskfOptions& o) {
  v.Boolean("estimate_gravity", o.estimate_gravity);
  v.Number("gravity_sigma_m_s2", o.gravity_sigma, kNoUnit, Positive());
  v.Integer("iterations", o.iterations, 1, 50);
  v.Number("covariance_interval_s", o.covariance_interval, kNoUnit, Within(0.0, 0.1));
};

inline constexpr auto kSmootherKeys = [](auto& v, SmootherOptions& o) {
  v.Integer("window_size", o.window_size, 2);
  v.Number("max_keyframe_interval_s", o.max_keyframe_interval, kNoUnit, Positive());
  v.Number("min_keyframe_interval_s", o.min_keyframe_interval, kNoUnit, NonNegative());
  v.Choice("linear_solver", o.linear_solver, Names({"dense_schur", "sparse_normal_cholesky"}));
  v.Integer("max_iterations", o.max_iterations, 1);
  v.Number("function_tolerance", o.function_tolerance, kNoUnit, Within(1e-12, 0.1));
  v.Integer("num_threads", o.num_threads, 1);
  v.Number("bias_reintegrate_threshold", o.bias_reintegrate_threshold, kNoUnit, NonNegative());
};

inline constexpr auto kBatchKeys = [](auto& v, BatchOptions& o) {
  v.Integer("max_iterations", o.max_iterations, 1);
  v.Number("function_tolerance", o.function_tolerance, kNoUnit, Within(1e-15, 0.1));
  v.Integer("max_relinearizations", o.max_relinearizations, 0);
  v.Boolean("revisit_fixes", o.revisit_fixes);
  v.Integer("max_segment_keyframes", o.max_segment_keyframes, 16);
  v.Integer("segment_overlap_keyframes", o.segment_overlap_keyframes, 4);
};

inline constexpr auto kStandstillKeys = [](auto& v, StandstillOptions& o) {
  v.Boolean("enabled", o.enabled);
  v.Number("window_s", o.window, kNoUnit, Positive());
  v.Number("max_gyro_std_deg_s", o.max_gyro_std, kDeg, Positive());
  v.Number("max_acc_std_m_s2", o.max_acc_std, kNoUnit, Positive());
  v.Number("velocity_sigma_m_s", o.velocity_sigma, kNoUnit, Positive());
  v.Number("max_speed_m_s", o.max_speed, kNoUnit, Positive());
};

inline constexpr auto kWatchdogKeys = [](auto& v, WatchdogOptions& o) {
  v.Boolean("enabled", o.enabled);
  v.Number("max_reject_s", o.max_reject, kNoUnit, Positive());
  v.Number("max_position_sigma_m", o.max_position_sigma, kNoUnit, Positive());
};

// An item of simulate.segments.
inline constexpr auto kSegmentKeys = [](auto& v, SimSegment& s) {
  v.Number("duration_s", s.duration, kNoUnit, Positive(), Presence::kRequired);
  v.Number("accel_m_s2", s.accel, kNoUnit, Within(-10.0, 10.0));
  v.Number("yaw_rate_deg_s", s.yaw_rate, kDeg, Within(-90.0, 90.0));
  v.Number("grade_deg", s.grade, kDeg, Within(-45.0, 45.0));
  v.Boolean("reverse", s.reverse);
};

// An item of simulate.raw_gnss_blocked.
inline constexpr auto kRawGnssBlockedKeys = [](auto& v, RawGnssBlockedWindow& w) {
  v.Number("start_s", w.start_s, kNoUnit, NonNegative(), Presence::kRequired);
  v.Number("duration_s", w.duration_s, kNoUnit, Positive(), Presence::kRequired);
  v.Integer("max_visible", w.max_visible, 0, 999);
};

// The raw observations of gins simulate (core/sim/raw_gnss.h): keys of the simulate section with a prefix,
// since a section holds keys, not sections.
inline constexpr auto kRawGnssKeys = [](auto& v, RawGnssSimConfig& o) {
  v.Boolean("raw_gnss_enabled", o.enabled);
  v.String("raw_gnss_nav_file", o.nav_file);
  v.Number("raw_gnss_rate_hz", o.rate_hz, kNoUnit, Positive());
  v.String("raw_gnss_gps_signals", o.gps_signals);
  v.String("raw_gnss_galileo_signals", o.galileo_signals);
  v.String("raw_gnss_beidou_signals", o.beidou_signals);
  RawGnssSimOptions& s = o.options;
  v.Number("raw_gnss_elevation_mask_deg", s.elevation_mask_deg, kNoUnit, Within(0.0, 89.0));
  v.Number("raw_gnss_clock_bias_s", s.clock_bias_s, kNoUnit, Within(-0.5, 0.5));
  v.Number("raw_gnss_clock_drift_s_s", s.clock_drift_s_s, kNoUnit, Within(-1e-4, 1e-4));
  v.Number("raw_gnss_clock_drift_rw_s_s_sqrt_s", s.clock_drift_rw_s_s_sqrt_s, kNoUnit, NonNegative());
  v.Number("raw_gnss_code_sigma_a_m", s.code_sigma_a_m, kNoUnit, NonNegative());
  v.Number("raw_gnss_code_sigma_b_m", s.code_sigma_b_m, kNoUnit, NonNegative());
  v.Number("raw_gnss_multipath_sigma_m", s.multipath_sigma_m, kNoUnit, NonNegative());
  v.Number("raw_gnss_multipath_tau_s", s.multipath_tau_s, kNoUnit, Positive());
  v.Number("raw_gnss_doppler_sigma_m_s", s.doppler_sigma_m_s, kNoUnit, NonNegative());
  v.Number("raw_gnss_phase_sigma_m", s.phase_sigma_m, kNoUnit, NonNegative());
  v.Boolean("raw_gnss_ionosphere", s.ionosphere);
  v.Boolean("raw_gnss_troposphere", s.troposphere);
  v.Number("raw_gnss_iono_residual_fraction", s.iono_residual_fraction, kNoUnit, NonNegative());
  v.Number("raw_gnss_tropo_residual_fraction", s.tropo_residual_fraction, kNoUnit, NonNegative());
  v.List("raw_gnss_blocked", "window", s.blocked, kRawGnssBlockedKeys);
};

inline constexpr auto kSimulateKeys = [](auto& v, SimOptions& o) {
  v.Integer("seed", o.seed, 0, std::numeric_limits<unsigned>::max());
  v.Number("start_time_s", o.start_time, kNoUnit, NonNegative());
  v.Origin("origin", o.origin);  // required to be a point: a simulation needs somewhere to start
  v.Number("initial_heading_deg", o.initial_yaw, kCompassDeg, Within(-360.0, 360.0));
  v.List("segments", "segment", o.segments, kSegmentKeys);
  v.Integer("repeat", o.repeat, 1, 100000);
  v.Number("imu_rate_hz", o.imu_rate, kNoUnit, Positive());
  v.Number("gnss_rate_hz", o.gnss_rate, kNoUnit, Positive());
  v.Number("wheel_rate_hz", o.wheel_rate, kNoUnit, Positive());
  // True errors may be zero (a perfect sensor), unlike the estimator's noise models.
  v.Number("gyro_noise_deg_sqrt_h", o.gyro_noise_density, kDegPerSqrtH, NonNegative());
  v.Number("acc_noise_m_s_sqrt_h", o.acc_noise_density, kPerSqrtH, NonNegative());
  v.Number("gyro_bias_rw_deg_h_sqrt_h", o.gyro_bias_rw, kDegPerHPerSqrtH, NonNegative());
  v.Number("acc_bias_rw_m_s2_sqrt_h", o.acc_bias_rw, kPerSqrtH, NonNegative());
  v.Number("gyro_turn_on_bias_deg_h", o.gyro_turn_on_bias, kDegPerH, NonNegative());
  v.Number("acc_turn_on_bias_m_s2", o.acc_turn_on_bias, kNoUnit, NonNegative());
  v.Vector3("gnss_sigma_m", o.gnss_sigma_enu, "[east, north, up]", NonNegative());
  v.Boolean("write_gnss_sigma", o.write_gnss_sigma);
  v.Number("heading_sigma_deg", o.heading_sigma, kDeg, NonNegative());
  v.Number("heading_invalid_fraction", o.heading_invalid_fraction, kNoUnit, Fraction());
  v.Outages("gnss_outages_s", o.gnss_outages);
  v.Number("gnss_outlier_probability", o.gnss_outlier_probability, kNoUnit, Probability());
  v.Number("gnss_outlier_magnitude_m", o.gnss_outlier_magnitude, kNoUnit, NonNegative());
  v.Vector3("lever_arm_m", o.lever_b, kLeverWhat, kLeverCheck);
  v.Number("mount_yaw_deg", o.mount_yaw, kDeg, Within(-360.0, 360.0));
  v.Number("wheel_radius_m", o.wheel_radius, kNoUnit, Positive());
  v.Number("pulses_per_rev", o.pulses_per_rev, kNoUnit, Positive());
  v.Number("wheel_scale", o.wheel_scale, kNoUnit, Within(0.5, 1.5));
  v.Number("wheel_speed_noise_m_s", o.wheel_speed_noise, kNoUnit, NonNegative());
  v.Number("track_width_m", o.track_width, kNoUnit, Positive());
  v.Vector3("wheel_lever_arm_m", o.wheel_lever_b, kLeverWhat, kLeverCheck);
  v.Boolean("earth_rotation", o.earth_rotation);
  v.Vector3("gnss_velocity_sigma_m_s", o.gnss_velocity_sigma, "[east, north, up]", NonNegative());
  v.Number("gnss_noise_correlation_s", o.gnss_noise_correlation, kNoUnit, NonNegative());
  v.Number("log_start_s", o.log_start, kNoUnit, NonNegative());
  kRawGnssKeys(v, o.raw_gnss);
};

// The sections of a config file, in file order.
inline constexpr auto kOptionsKeys = [](auto& v, Options& o) {
  v.Section("input", o.input, kInputKeys);
  v.Section("imu", o.sensors.imu, kImuKeys);
  v.Section("gnss", o.sensors.gnss, kGnssKeys);
  v.Section("raw_gnss", o.sensors.gnss.raw, kRawGnssInputKeys);
  v.Section("wheel", o.sensors.wheel, kWheelKeys);
  v.Section("vehicle", o.sensors.vehicle, kVehicleKeys);
  v.Section("gravity", o.sensors.gravity, kGravityKeys);
  MeasurementModules::ForEach([&](auto tag) {  // each measurement module's section (core/measurement_modules.h)
    using Mod = typename decltype(tag)::type;
    v.Section(Mod::Options::kSection, std::get<typename Mod::Options>(o.sensors.modules), Mod::Options::kKeys);
  });
  v.Section("init", o.init, kInitKeys);
  v.Section("eskf", o.eskf, kEskfKeys);
  v.Section("smoother", o.smoother, kSmootherKeys);
  v.Section("batch", o.batch, kBatchKeys);
  v.Section("standstill", o.standstill, kStandstillKeys);
  v.Section("watchdog", o.watchdog, kWatchdogKeys);
  v.Section("simulate", o.simulate, kSimulateKeys);
};

}  // namespace gins::config_internal
