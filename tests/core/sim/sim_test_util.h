// Drives and helpers shared by the simulator's tests of the rotating Earth and the field-log set-ups.
#pragma once

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <string>
#include <vector>

#include "core/sim/simulator.h"

namespace gins::test {

// Every sensor perfect (and every heading valid).
inline SimOptions NoiseFreeSim(SimOptions sim) {
  sim.gyro_noise_density = sim.acc_noise_density = 0.0;
  sim.gyro_bias_rw = sim.acc_bias_rw = 0.0;
  sim.gyro_turn_on_bias = sim.acc_turn_on_bias = 0.0;
  sim.gnss_sigma_enu.setZero();
  sim.heading_sigma = 0.0;
  sim.heading_invalid_fraction = 0.0;
  sim.gnss_outlier_probability = 0.0;
  sim.wheel_speed_noise = 0.0;
  return sim;
}

// 600 s, ~9 km from the origin (where the local vertical leans 1.4 mrad from w's): standstill, up to 27 m/s,
// hills, long curves, a left turn, a stop (469.75-483.75 s), backing up in a left curve, a stop (504.75-508.75 s)
// and driving off. The brakings end exactly at zero speed as their deceleration ramps out, so a_w has no
// step (no stop under a clamped deceleration: kernel integration tests can extrapolate in dt).
inline SimOptions FarDrive() {
  SimOptions sim;
  sim.seed = 11;
  sim.initial_yaw = 0.2;
  sim.segments = {{10.0, 0.0, 0.0, 0.0},         {25.0, 1.0, 0.0, 0.0},     {60.0, 0.0, 0.0, 0.05},
                  {60.0, 0.0, 0.01, -0.03},      {60.0, 0.0, -0.012, 0.0},  {20.0, -0.5, 0.0, 0.0},
                  {30.0, 0.0, 0.05, 0.0},        {40.0, 0.3, 0.0, 0.02},    {130.0, 0.0, 0.0, 0.0},
                  {33.75, -0.8, 0.0, 0.0},       {15.0, 0.0, 0.0, 0.0},     {10.0, 0.6, 0.08, 0.0, true},
                  {10.0, -0.6, 0.0, 0.0, true},  {5.0, 0.0, 0.0, 0.0, true}, {91.25, 0.25, -0.01, 0.0}};
  return sim;
}

inline std::vector<SimRecord> RunAll(const SimOptions& options) {
  Simulator sim(options);
  std::vector<SimRecord> out;
  SimRecord r;
  while (sim.Next(&r)) out.push_back(r);
  return out;
}

template <typename R>
std::vector<SimRecord> OfType(const std::vector<SimRecord>& all) {
  std::vector<SimRecord> out;
  std::copy_if(all.begin(), all.end(), std::back_inserter(out), [](const SimRecord& r) { return r.is<R>(); });
  return out;
}

// A measured number for RecordProperty, to 3 significant digits.
inline std::string Sig3(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g", v);
  return text;
}

}  // namespace gins::test
