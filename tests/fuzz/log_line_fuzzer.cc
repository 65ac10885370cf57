// libFuzzer target: ParseLogLine (core/log_reader.h) on one arbitrary line. Checks the parser's promises:
// it never crashes, a record it accepts is finite and within the plausibility limits, and a damaged line
// always carries a reason and a one-line detail.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/io/log_reader.h"

namespace {

void Require(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  gins::LogRecord record;
  gins::InputIssue issue;
  switch (gins::ParseLogLine(line, &record, &issue)) {
    case gins::LineParse::kBlank:
      break;
    case gins::LineParse::kDamaged:
      Require(!issue.reason.empty());
      Require(issue.detail.find('\n') == std::string::npos);
      break;
    case gins::LineParse::kRecord:
      Require(std::isfinite(record.t()) && record.t() > 0.0);
      switch (record.type) {
        case gins::LogRecord::Type::kImu:
          Require(record.imu.gyro.allFinite() && record.imu.acc.allFinite());
          break;
        case gins::LogRecord::Type::kWheel:
          Require(std::isfinite(record.wheel.left_pulses) && std::isfinite(record.wheel.right_pulses));
          break;
        case gins::LogRecord::Type::kGnssVelocity:
          Require(record.gnss_velocity.v_enu.allFinite() && record.gnss_velocity.v_enu.cwiseAbs().maxCoeff() <= 1000.0);
          Require(!record.gnss_velocity.has_sigma || (record.gnss_velocity.sigma_enu.minCoeff() > 0.0 && record.gnss_velocity.sigma_enu.allFinite()));
          break;
        case gins::LogRecord::Type::kGnss: {
          const gins::GnssRecord& g = record.gnss;
          Require(std::abs(g.lat_deg) <= 90.0 && std::abs(g.lon_deg) <= 180.0 && std::isfinite(g.alt_m));
          Require(g.heading_deg >= 0.0 && g.heading_deg < 360.0);
          Require(!g.has_sigma || (g.sigma_enu.minCoeff() > 0.0 && g.sigma_enu.allFinite()));
          break;
        }
      }
      break;
  }
  return 0;
}
