// Between the public API's plain structs (gins/gins.h) and gins's internal types. Plain copies of the
// doubles, so a state that goes out through the API and back (`gins run`'s writer) is bit for bit the same.
#pragma once

#include "core/io/log_reader.h"
#include "gins/gins.h"
#include "solver/estimator.h"

namespace gins::api {

LogRecord ToLogRecord(const Imu& m);
LogRecord ToLogRecord(const Wheel& m);
LogRecord ToLogRecord(const Gnss& m);
LogRecord ToLogRecord(const GnssVelocity& m);
LogRecord ToLogRecord(const Record& r);
Record ToRecord(const LogRecord& r);

// Everything but State::lla.
void ToState(Stream stream, const StateEstimate& e, State* out);
StateEstimate ToStateEstimate(const State& s);

}  // namespace gins::api
