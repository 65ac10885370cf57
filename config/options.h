// Typed options: every setting gins reads, in SI units, with in-class defaults equal to
// config/default.yaml. Each component declares the sections it reads next to itself (core/sensors.h,
// core/initializer.h, core/standstill_detector.h, core/io/log_reader.h, core/sim/simulator.h,
// solver/estimator_options.h) and takes only those, each by const reference: the sensors (SensorOptions)
// plus its own sections, never the whole. Options is the plain aggregate of the sections, the whole of one
// config file; no option struct derives from another. The YAML loader (config/config_loader.h) is the only
// code that reads YAML; it converts the users' units (named in each key) to SI once, validates ranges and
// rejects unknown keys.
#pragma once

#include "core/initializer.h"
#include "core/io/log_reader.h"
#include "core/sensors.h"
#include "core/sim/simulator.h"
#include "core/standstill_detector.h"
#include "solver/estimator_options.h"

namespace gins {

struct Options {
  InputOptions input;            // input.*: how the log is read
  SensorOptions sensors;         // imu.*, gnss.*, raw_gnss.*, wheel.*, vehicle.*, gravity.*
  InitOptions init;              // init.*
  StandstillOptions standstill;  // standstill.*
  EskfOptions eskf;              // eskf.*
  SmootherOptions smoother;      // smoother.*
  BatchOptions batch;            // batch.*
  WatchdogOptions watchdog;      // watchdog.*
  SimOptions simulate;           // simulate.* (only `gins simulate` reads it)
};

// What a log reader takes from a config: input.*, and the IMU's range from imu.* (a reading beyond it is
// damage).
inline InputOptions ReaderOptions(const Options& o) {
  InputOptions in = o.input;
  in.imu_range = {o.sensors.imu.max_gyro, o.sensors.imu.max_acc};
  return in;
}

}  // namespace gins
