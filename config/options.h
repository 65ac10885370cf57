// Typed options: every setting gins reads, in SI units, with in-class defaults equal to
// config/default.yaml. Each component declares the options it takes next to itself (core/sensors.h,
// core/initializer.h, core/standstill_detector.h, core/io/log_reader.h, core/sim/simulator.h,
// solver/estimator_options.h); this is their sum, the whole of one config file. The YAML
// loader (config/config_loader.h) is the only code that reads YAML; it converts the users' units (named in
// each key) to SI once, validates ranges and rejects unknown keys.
#pragma once

#include "core/io/log_reader.h"
#include "core/sim/simulator.h"
#include "solver/estimator_options.h"

namespace gins {

struct Options : EstimatorOptions {
  InputOptions input;   // input.*: how the log is read
  SimOptions simulate;  // simulate.* (only `gins simulate` reads it)
};

// What a log reader takes from a config: input.*, and the IMU's range from imu.* (a reading beyond it is
// damage).
inline InputOptions ReaderOptions(const Options& o) {
  InputOptions in = o.input;
  in.imu_range = {o.imu.max_gyro, o.imu.max_acc};
  return in;
}

}  // namespace gins
