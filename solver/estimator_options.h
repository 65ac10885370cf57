// The estimators' own sections of the options (eskf.*, smoother.*, batch.*, watchdog.*); the sensors', the
// initialisation's and the standstill detector's are declared in core/. config/ fills them from YAML; each
// estimator takes the sections it reads.
#pragma once

#include <string>

#include "core/sensors.h"

namespace gins {

// eskf.*
struct EskfOptions {
  bool estimate_gravity = true;     // eskf.estimate_gravity: δg in the error state
  double gravity_sigma = 0.01;      // eskf.gravity_sigma_m_s2 initial 1-σ per axis
  int iterations = 3;               // eskf.iterations: at most this many linearisations per update
  double covariance_interval = 0.02;  // eskf.covariance_interval_s: the covariance steps over up to this long
};

// smoother.*
struct SmootherOptions {
  int window_size = 10;             // smoother.window_size: keyframes in the window
  double max_keyframe_interval = 1.0;  // smoother.max_keyframe_interval_s
  double min_keyframe_interval = 0.5;  // smoother.min_keyframe_interval_s: faster GNSS makes no keyframe
  std::string linear_solver = "sparse_normal_cholesky";  // smoother.linear_solver: sparse_normal_cholesky | dense_schur
  int max_iterations = 10;          // smoother.max_iterations
  double function_tolerance = 1e-6;  // smoother.function_tolerance: stop when |Δcost|/cost falls below
  int num_threads = 1;              // smoother.num_threads
  double bias_reintegrate_threshold = 1e-3;  // smoother.bias_reintegrate_threshold (norm of δbg, rad/s)
};

// batch.*: the whole-log smoother (--mode batch; solver/batch_smoother.h).
struct BatchOptions {
  int max_iterations = 50;          // batch.max_iterations
  double function_tolerance = 1e-9;  // batch.function_tolerance: stop when |Δcost|/cost falls below
  int max_relinearizations = 2;     // batch.max_relinearizations: IMU re-integration rounds at the solution
  bool revisit_fixes = true;        // batch.revisit_fixes: GNSS decisions checked again on the solution
  int max_segment_keyframes = 20000;     // batch.max_segment_keyframes: longer logs are solved in segments
  int segment_overlap_keyframes = 200;   // batch.segment_overlap_keyframes: the segments' overlap
};

// watchdog.*: divergence detection and re-initialisation from GNSS.
struct WatchdogOptions {
  bool enabled = true;                // watchdog.enabled
  double max_reject = 15.0;           // watchdog.max_reject_s: every GNSS fix rejected for this long
  double max_position_sigma = 100.0;  // watchdog.max_position_sigma_m: position 1-σ that counts as exploded
};

// The odometer scale is a state (the ESKF's δs, the keyframes' scale block) only with wheels and
// wheel.estimate_scale.
inline bool OdometerScaleEstimated(const SensorOptions& o) { return o.wheel.enabled && o.wheel.estimate_scale; }

}  // namespace gins
