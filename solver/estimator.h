// The Estimator interface both the ESKF and the smoother implement. Measurements flow one way:
// reader -> time-ordered measurement stream -> estimator -> state sink. What the two estimators share beyond
// it (counts, the watchdog, the re-initialisation from a fix, ...) is in solver/estimator_common.h.
#pragma once

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/gnss_raw.h"
#include "core/initializer.h"
#include "core/measurements.h"
#include "core/nav_state.h"

namespace gins {

// One output state with its uncertainty.
struct StateEstimate {
  NavState x;
  Vec3 sigma_p = Vec3::Zero();      // m, world axes
  Vec3 sigma_v = Vec3::Zero();      // m/s, world axes
  Vec3 sigma_att = Vec3::Zero();    // rad, rotation about the world axes (E, N, U: the last is yaw)
  double odom_scale = 1.0;
};

using StateCallback = std::function<void(const StateEstimate&)>;

class Estimator {
 public:
  virtual ~Estimator() = default;
  virtual std::string name() const = 0;
  // Starts from a static initialisation; states are then emitted through the callback.
  virtual void Initialize(const InitResult& init) = 0;
  virtual void AddImu(const ImuSample& imu) = 0;
  virtual void AddGnss(const GnssMeasurement& gnss) = 0;
  // A GNSS velocity, after the fix of the same epoch (if any).
  virtual void AddGnssVelocity(const GnssVelocityMeasurement& gnss_velocity) = 0;
  virtual void AddWheel(const WheelMeasurement& wheel) = 0;
  // The vehicle stands (the session's detector: wheels at zero and IMU quiet, or IMU quiet without
  // wheels); sent at most every 0.1 s while it stands, right after the IMU sample at m.t.
  virtual void AddStandstill(const StandstillMeasurement& m) = 0;
  // A raw GNSS epoch (core/gnss_raw.h), in time order with the rest; it carries its own single-point fix for
  // an estimator that takes fixes only.
  virtual void AddRawGnss(const RawGnssMeasurement& m) = 0;
  // Before Initialize: a state at rest that the initialiser knows without a yaw (Initializer::RestStates),
  // in time order and before the initialisation's time; written to the forward outputs, and to the
  // two-sided ones with the yaw found later (solver/pre_init_output.h).
  virtual void AddRestState(const StateEstimate& s) = 0;
  // End of the log: flush everything still held.
  virtual void Finish() = 0;
  virtual nlohmann::json Stats() const = 0;
};

}  // namespace gins
