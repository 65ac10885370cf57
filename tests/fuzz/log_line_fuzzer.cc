// libFuzzer target: ParseLogLine (core/log_reader.h) on one arbitrary line. Checks the parser's promises:
// it never crashes, a record it accepts is finite and within the plausibility limits, and a damaged line
// always carries a reason and a one-line detail.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <variant>

#include "core/io/log_reader.h"

namespace {

void Require(bool ok) {
  if (!ok) std::abort();
}

// An accepted record, per type.
void RequireSane(const gins::ImuSample& m) { Require(m.gyro.allFinite() && m.acc.allFinite()); }

void RequireSane(const gins::WheelRecord& w) {
  Require(std::isfinite(w.left_pulses) && std::isfinite(w.right_pulses));
}

void RequireSane(const gins::GnssRecord& g) {
  Require(std::abs(g.lat_deg) <= 90.0 && std::abs(g.lon_deg) <= 180.0 && std::isfinite(g.alt_m));
  Require(g.heading_deg >= 0.0 && g.heading_deg < 360.0);
  Require(!g.has_sigma || (g.sigma_enu.minCoeff() > 0.0 && g.sigma_enu.allFinite()));
}

void RequireSane(const gins::GnssVelocityRecord& v) {
  Require(v.v_enu.allFinite() && v.v_enu.cwiseAbs().maxCoeff() <= 1000.0);
  Require(!v.has_sigma || (v.sigma_enu.minCoeff() > 0.0 && v.sigma_enu.allFinite()));
}

template <typename R>  // a measurement module's record: its numbers finite, and back as they were read
void RequireSane(const R& r) {
  double v[gins::RecordTraits<R>::kInfo.max_fields];
  const size_t n = R::Values(r, v);
  Require(n >= gins::RecordTraits<R>::kInfo.min_fields && n <= gins::RecordTraits<R>::kInfo.max_fields);
  for (size_t i = 0; i < n; ++i) Require(std::isfinite(v[i]));
  Require(R::Absurd(v, n).empty());
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
      std::visit([](const auto& m) { RequireSane(m); }, record.data);
      break;
  }
  return 0;
}
