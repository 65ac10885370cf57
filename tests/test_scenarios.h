// Seeded drives shared by the end-to-end tests of both estimators.
#pragma once

#include "config/options.h"

namespace gins::test {

// About four minutes: a 20 s standstill, then speed changes up to ~15 m/s, left and right turns, a hill up
// and down, a 10 s stop, and one 20 s GNSS outage while driving. Sensors: low-cost MEMS IMU (as in
// config/default.yaml), 1 Hz RTK-like GNSS with dual-antenna heading, 10 Hz wheel pulses with a 1 % scale
// error; the vehicle geometry of the reference book.
inline SimOptions TestDrive(unsigned seed) {
  SimOptions s;
  s.seed = seed;
  s.start_time = 1700000000.0;
  s.origin = {31.5, 120.4, 10.0};
  s.initial_yaw = 0.3;
  const double d = kDegToRad;
  s.segments = {
      {20.0, 0.0, 0.0, 0.0},       // standstill
      {10.0, 1.0, 0.0, 0.0},       // accelerate to 10 m/s
      {15.0, 0.0, 6.0 * d, 0.0},   // left turn, 90°
      {15.0, 0.3, 0.0, 3.0 * d},   // uphill, speeding up
      {10.0, 0.0, 0.0, 0.0},       // crest
      {15.0, -0.2, 0.0, -3.0 * d}, // downhill
      {10.0, 0.0, -9.0 * d, 0.0},  // right turn, 90°
      {10.0, -1.0, 0.0, 0.0},      // brake to a stop
      {10.0, 0.0, 0.0, 0.0},       // stopped
      {12.0, 1.2, 0.0, 0.0},       // accelerate
      {30.0, 0.0, 0.0, 0.0},       // cruise (the outage is here)
      {20.0, 0.0, 4.5 * d, 0.0},   // long gentle left turn
      {15.0, -0.5, -3.0 * d, 0.0}, // slow down while turning
      {20.0, 0.0, 0.0, 0.0},
  };
  s.imu_rate = 100.0;
  s.gnss_rate = 1.0;
  s.wheel_rate = 10.0;
  s.gyro_noise_density = 0.5 * d / 60.0;
  s.acc_noise_density = 0.05 / 60.0;
  s.gyro_bias_rw = 10.0 * d / 3600.0 / 60.0;
  s.acc_bias_rw = 0.002 / 60.0;
  s.gyro_turn_on_bias = 100.0 * d / 3600.0;
  s.acc_turn_on_bias = 0.03;
  s.gnss_sigma_enu = Vec3(0.02, 0.02, 0.03);
  s.heading_sigma = 0.2 * d;
  s.heading_invalid_fraction = 0.05;
  s.gnss_outages = {{125.0, 20.0}};
  s.wheel_scale = 0.99;
  s.wheel_speed_noise = 0.02;
  return s;
}

// Run options matching TestDrive's vehicle, with the world frame at the simulation's origin so truth and
// estimates share coordinates.
inline Options TestRunOptions(const SimOptions& sim) {
  Options o;
  o.sensors.gnss.origin = sim.origin;
  o.sensors.gnss.lever_b = sim.lever_b;
  o.sensors.gnss.mount_yaw = sim.mount_yaw;
  o.sensors.wheel.radius = sim.wheel_radius;
  o.sensors.wheel.pulses_per_rev = sim.pulses_per_rev;
  o.sensors.wheel.interval = 1.0 / sim.wheel_rate;
  // The simulated GNSS is stamped at its measurement time: stated, as a config states a known latency (the
  // default estimates it, at the cost of its σ along the track; cli_test's time-offset test covers that).
  o.sensors.gnss.time_offset = 0.0;
  o.sensors.gnss.estimate_time_offset = false;
  return o;
}

}  // namespace gins::test
