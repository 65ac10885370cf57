// A record of the log (docs/formats.md §3), the one record type below the public API: what the reader yields,
// what the simulator generates (core/sim/simulator.h: SimRecord, with its truth), what the writer writes and
// what the solver's EstimatorPipeline takes (EstimatorPipeline::Add). A switch over Type is written where a
// type's own code is chosen (parsing, writing, dispatch), never for the time stamp.
#pragma once

#include <cstdint>

#include "core/measurements.h"

namespace gins {

struct LogRecord {
  enum class Type { kImu, kWheel, kGnss, kGnssVelocity };
  static constexpr int kNumTypes = 4;
  Type type = Type::kImu;
  uint64_t line = 0;  // 1-based line number in the file
  ImuSample imu;      // valid when type == kImu
  WheelRecord wheel;    // valid when type == kWheel
  GnssRecord gnss;    // valid when type == kGnss
  GnssVelocityRecord gnss_velocity;    // valid when type == kGnssVelocity
  double t() const;
  void set_t(double t);  // of the member that type names
};

// "IMU", "ODOM", "GNSS" or "GVEL": the record's type token.
const char* LogRecordTypeName(LogRecord::Type type);

}  // namespace gins
