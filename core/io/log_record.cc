#include "core/io/log_record.h"

namespace gins {
namespace {

// The time stamp of the member that type names.
template <typename Record>
auto& Stamp(Record& r) {
  switch (r.type) {
    case LogRecord::Type::kImu:
      return r.imu.t;
    case LogRecord::Type::kWheel:
      return r.wheel.t;
    case LogRecord::Type::kGnss:
      return r.gnss.t;
    case LogRecord::Type::kGnssVelocity:
      return r.gnss_velocity.t;
  }
  return r.imu.t;
}

}  // namespace

double LogRecord::t() const { return Stamp(*this); }
void LogRecord::set_t(double t) { Stamp(*this) = t; }

const char* LogRecordTypeName(LogRecord::Type type) {
  switch (type) {
    case LogRecord::Type::kImu:
      return "IMU";
    case LogRecord::Type::kWheel:
      return "ODOM";
    case LogRecord::Type::kGnss:
      return "GNSS";
    case LogRecord::Type::kGnssVelocity:
      return "GVEL";
  }
  return "?";
}

}  // namespace gins
