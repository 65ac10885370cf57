// The Estimator interface both the ESKF and the smoother implement. Measurements flow one way:
// reader -> time-ordered measurement stream -> estimator -> state sink. What the two estimators share beyond
// it (counts, the watchdog, the re-initialisation from a fix, ...) is in solver/estimator_common.h.
#pragma once

#include <functional>
#include <string>
#include <variant>

#include <nlohmann/json.hpp>

#include "core/gnss_raw.h"
#include "core/initializer.h"
#include "core/measurement_modules.h"
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

// Every measurement an estimator takes besides the IMU: one alternative per type, registered here and
// nowhere else. The estimators and the smoother's attachers visit it, so a type that one of them does not
// handle is a compile error. In time order with the IMU samples, and:
// - a GNSS velocity comes after the fix of the same epoch (if any);
// - a standstill (the pipeline's detector: wheels at zero and IMU quiet, or IMU quiet without wheels) at
//   most every 0.1 s while the vehicle stands, right after the IMU sample at its time;
// - a raw GNSS epoch (core/gnss_raw.h) carries its own single-point fix, for an estimator that takes fixes
//   only;
// - a measurement module's (core/measurement_modules.h) comes at its record's time.
using Measurement = MeasurementModules::MeasurementsAfter<GnssMeasurement, GnssVelocityMeasurement, WheelMeasurement,
                                                          StandstillMeasurement, RawGnssMeasurement>;

class Estimator {
 public:
  virtual ~Estimator() = default;
  virtual std::string name() const = 0;
  // Starts from a static initialisation; states are then emitted through the callback.
  virtual void Initialize(const InitResult& init) = 0;
  virtual void AddImu(const ImuSample& imu) = 0;
  virtual void Add(const Measurement& m) = 0;
  // Before Initialize: a state at rest that the initialiser knows without a yaw (Initializer::RestStates),
  // in time order and before the initialisation's time; written to the forward outputs, and to the
  // two-sided ones with the yaw found later (solver/pre_init_output.h).
  virtual void AddRestState(const StateEstimate& s) = 0;
  // End of the log: flush everything still held.
  virtual void Finish() = 0;
  virtual nlohmann::json Stats() const = 0;
};

}  // namespace gins
