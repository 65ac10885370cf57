// ParseLogLine (core/io/log_reader.h): one line of the gins log format, with every check that needs no
// other line.
#include <algorithm>
#include <array>
#include <iterator>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>

#include "core/io/log_reader.h"

namespace gins {
namespace {

using input_reason::kAbsurdValue;
using input_reason::kBadNumber;
using input_reason::kExtraFields;
using input_reason::kMissingFields;
using input_reason::kNonFinite;
using input_reason::kUnknownType;
using log_limits::kMaxAbsHeadingDeg;
using log_limits::kMaxAbsLatDeg;
using log_limits::kMaxAbsLonDeg;
using log_limits::kMaxAbsPulses;
using log_limits::kMaxAlt;
using log_limits::kMaxSigma;
using log_limits::kMinAlt;

// Names of the numeric fields after the type token, for messages.
constexpr const char* kImuFields[] = {"t", "gx", "gy", "gz", "ax", "ay", "az"};
constexpr const char* kWheelFields[] = {"t", "left_pulses", "right_pulses"};
constexpr const char* kGnssFields[] = {"t",       "lat",     "lon",    "alt", "heading", "heading_valid",
                                       "sigma_e", "sigma_n", "sigma_u"};
constexpr const char* kGnssVelocityFields[] = {"t", "ve", "vn", "vu", "sigma_e", "sigma_n", "sigma_u"};
constexpr size_t kMaxNumbers = 9;               // GNSS with σ
constexpr size_t kMaxTokens = kMaxNumbers + 1;  // plus the type

inline bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Splits a line into whitespace-separated views without copying. count is the total number of tokens,
// which may exceed the kMaxTokens kept (enough to report extra fields).
struct Tokens {
  std::array<std::string_view, kMaxTokens> tok;
  size_t count = 0;
};

void Tokenize(std::string_view line, Tokens* tokens) {
  const char* p = line.data();
  const char* const end = p + line.size();
  tokens->count = 0;
  for (;;) {
    while (p < end && IsSpace(*p)) ++p;
    if (p == end) break;
    const char* const start = p;
    while (p < end && !IsSpace(*p)) ++p;
    if (tokens->count < kMaxTokens) tokens->tok[tokens->count] = std::string_view(start, p - start);
    ++tokens->count;
  }
}

LineParse Damaged(InputIssue* issue, const char* reason, std::string detail) {
  issue->reason = reason;
  issue->detail = std::move(detail);
  return LineParse::kDamaged;
}

// "field 4 (gy) = 40 rad/s, beyond ±35": fields are numbered like awk's, the type being field 1.
std::string FieldValue(size_t index, const char* name, double value) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "field %zu (%s) = %.10g", index + 2, name, value);
  return buf;
}

std::string Num(double value) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%g", value);
  return buf;
}

// Range checks on parsed numbers; returns the detail of the first absurd field, or empty.
std::string CheckImu(const double* v, const ImuRange& range) {
  for (size_t i = 1; i <= 3; ++i) {
    if (std::abs(v[i]) > range.max_gyro) {
      return FieldValue(i, kImuFields[i], v[i]) + " rad/s, beyond ±" + Num(range.max_gyro) + " (imu.max_gyro_rad_s)";
    }
  }
  for (size_t i = 4; i <= 6; ++i) {
    if (std::abs(v[i]) > range.max_acc) {
      return FieldValue(i, kImuFields[i], v[i]) + " m/s², beyond ±" + Num(range.max_acc) + " (imu.max_acc_m_s2)";
    }
  }
  return {};
}

std::string CheckOdom(const double* v) {
  for (size_t i = 1; i <= 2; ++i) {
    if (!(std::abs(v[i]) < kMaxAbsPulses)) {
      return FieldValue(i, kWheelFields[i], v[i]) + ", |pulses| must be < " + Num(kMaxAbsPulses);
    }
  }
  return {};
}

std::string CheckGnss(const double* v, size_t n) {
  if (std::abs(v[1]) > kMaxAbsLatDeg) {
    return FieldValue(1, "lat", v[1]) + " deg, beyond ±" + Num(kMaxAbsLatDeg);
  }
  if (std::abs(v[2]) > kMaxAbsLonDeg) {
    return FieldValue(2, "lon", v[2]) + " deg, beyond ±" + Num(kMaxAbsLonDeg);
  }
  if (!(v[3] > kMinAlt && v[3] < kMaxAlt)) {
    return FieldValue(3, "alt", v[3]) + " m, outside (" + Num(kMinAlt) + ", " + Num(kMaxAlt) + ")";
  }
  if (v[5] != 0.0 && v[5] != 1.0) return FieldValue(5, "heading_valid", v[5]) + ", must be 0 or 1";
  // An invalid heading is a placeholder the receiver may fill with anything; the fix is still a position.
  if (v[5] == 1.0 && std::abs(v[4]) > kMaxAbsHeadingDeg) {
    return FieldValue(4, "heading", v[4]) + " deg, outside ±" + Num(kMaxAbsHeadingDeg);
  }
  for (size_t i = 6; i < n; ++i) {
    if (!(v[i] > 0.0 && v[i] < kMaxSigma)) {
      return FieldValue(i, kGnssFields[i], v[i]) + " m, σ must be in (0, " + Num(kMaxSigma) + ")";
    }
  }
  return {};
}

std::string CheckGnssVelocity(const double* v, size_t n) {
  for (size_t i = 1; i <= 3; ++i) {
    if (!(std::abs(v[i]) <= log_limits::kMaxAbsSpeed)) {
      return FieldValue(i, kGnssVelocityFields[i], v[i]) + " m/s, beyond ±" + Num(log_limits::kMaxAbsSpeed);
    }
  }
  for (size_t i = 4; i < n; ++i) {
    if (!(v[i] > 0.0 && v[i] < log_limits::kMaxAbsSpeed)) {
      return FieldValue(i, kGnssVelocityFields[i], v[i]) + " m/s, σ must be in (0, " + Num(log_limits::kMaxAbsSpeed) + ")";
    }
  }
  return {};
}

// Heading in [-360, 360] -> [0, 360).
double NormaliseHeading(double h) {
  h = std::fmod(h, 360.0);
  if (h < 0.0) h += 360.0;
  if (h >= 360.0 || h == 0.0) h = 0.0;  // -1e-20 + 360 rounds to 360; -0 becomes +0
  return h;
}

// The record type from the first token, with the names of its fields and how many numbers it needs
// (GNSS: 6, or 9 with σ); false for an unknown type.
bool ClassifyType(const Tokens& tokens, LogRecord* record, const char* const** names, size_t* expected) {
  const std::string_view type = tokens.tok[0];
  if (type == "IMU") {
    record->type = LogRecord::Type::kImu;
    *names = kImuFields;
    *expected = 7;
  } else if (type == "ODOM") {
    record->type = LogRecord::Type::kWheel;
    *names = kWheelFields;
    *expected = 3;
  } else if (type == "GNSS") {
    record->type = LogRecord::Type::kGnss;
    *names = kGnssFields;
    *expected = tokens.count - 1 >= 9 ? 9 : 6;
  } else if (type == "GVEL") {
    record->type = LogRecord::Type::kGnssVelocity;
    *names = kGnssVelocityFields;
    *expected = tokens.count - 1 >= 7 ? 7 : 4;
  } else {
    return false;
  }
  return true;
}

// Field counts are of the values after the type; the message lists what the type needs.
LineParse CheckFieldCount(LogRecord::Type type, const char* const* names, size_t n, size_t expected,
                          InputIssue* issue) {
  // GNSS and GVEL take their three σ columns all or none.
  const bool gnss = type == LogRecord::Type::kGnss, gnss_velocity = type == LogRecord::Type::kGnssVelocity;
  const size_t with_sigma = gnss ? 9 : 7;
  if ((gnss || gnss_velocity) && n > with_sigma - 3 && n < with_sigma) {
    return Damaged(issue, kMissingFields,
                   std::string(LogRecordTypeName(type)) + " has " + std::to_string(n) +
                       " values; sigma_e sigma_n sigma_u come all three or none");
  }
  if (n != expected) {
    const bool optional = gnss || gnss_velocity;
    std::string detail = std::string(LogRecordTypeName(type)) + " has " + std::to_string(n) + " values, needs " +
                         (optional ? std::to_string(with_sigma - 3) + " or " + std::to_string(with_sigma)
                                   : std::to_string(expected)) +
                         ":";
    for (size_t i = 0; i < (optional ? with_sigma : expected); ++i) detail += std::string(" ") + names[i];
    if (optional) detail += " (sigma optional)";
    return Damaged(issue, n < expected ? kMissingFields : kExtraFields, std::move(detail));
  }
  return LineParse::kRecord;
}

// Range checks of a record's n finite numbers v (in log field order): one rule for parsed lines and for
// records pushed through the API.
LineParse CheckValues(LogRecord::Type type, size_t n, const double* v, const ImuRange& range, InputIssue* issue) {
  if (!(v[0] > 0.0)) return Damaged(issue, kAbsurdValue, FieldValue(0, "t", v[0]) + ", time must be > 0");
  if (!(v[0] < log_limits::kMaxTime)) {
    return Damaged(issue, kAbsurdValue,
                   FieldValue(0, "t", v[0]) + " s, beyond " + Num(log_limits::kMaxTime) + " s (not seconds?)");
  }
  std::string absurd;
  switch (type) {
    case LogRecord::Type::kImu:
      absurd = CheckImu(v, range);
      break;
    case LogRecord::Type::kWheel:
      absurd = CheckOdom(v);
      break;
    case LogRecord::Type::kGnss:
      absurd = CheckGnss(v, n);
      break;
    case LogRecord::Type::kGnssVelocity:
      absurd = CheckGnssVelocity(v, n);
      break;
  }
  if (!absurd.empty()) return Damaged(issue, kAbsurdValue, std::move(absurd));
  return LineParse::kRecord;
}

// Parses the n numbers after the type into v, then checks their ranges.
LineParse ParseValues(const Tokens& tokens, LogRecord::Type type, const char* const* names, size_t n, double* v,
                      const ImuRange& range, InputIssue* issue) {
  for (size_t i = 0; i < n; ++i) {
    const NumberStatus status = ParseNumber(tokens.tok[i + 1], &v[i]);
    if (status == NumberStatus::kOk) continue;
    const std::string field =
        "field " + std::to_string(i + 2) + " (" + names[i] + ") " + QuoteToken(tokens.tok[i + 1]);
    if (status == NumberStatus::kBad) return Damaged(issue, kBadNumber, field + " is not a number");
    return Damaged(issue, kNonFinite, field + " is not finite");
  }
  return CheckValues(type, n, v, range, issue);
}

void FillRecord(const double* v, size_t n, LogRecord* record) {
  switch (record->type) {
    case LogRecord::Type::kImu:
      record->imu.t = v[0];
      record->imu.gyro = Vec3(v[1], v[2], v[3]);
      record->imu.acc = Vec3(v[4], v[5], v[6]);
      break;
    case LogRecord::Type::kWheel:
      record->wheel.t = v[0];
      record->wheel.left_pulses = v[1];
      record->wheel.right_pulses = v[2];
      break;
    case LogRecord::Type::kGnss: {
      GnssRecord& g = record->gnss;
      g.t = v[0];
      g.lat_deg = v[1];
      g.lon_deg = v[2];
      g.alt_m = v[3];
      g.heading_valid = v[5] == 1.0;
      g.heading_deg = g.heading_valid ? NormaliseHeading(v[4]) : 0.0;
      g.has_sigma = n == 9;
      g.sigma_enu = g.has_sigma ? Vec3(v[6], v[7], v[8]) : Vec3::Zero();
      break;
    }
    case LogRecord::Type::kGnssVelocity: {
      GnssVelocityRecord& g = record->gnss_velocity;
      g.t = v[0];
      g.v_enu = Vec3(v[1], v[2], v[3]);
      g.has_sigma = n == 7;
      g.sigma_enu = g.has_sigma ? Vec3(v[4], v[5], v[6]) : Vec3::Zero();
      break;
    }
  }
}

// The numbers of a record in log field order (the inverse of FillRecord), with their names; returns n.
size_t RecordValues(const LogRecord& record, double* v, const char* const** names) {
  switch (record.type) {
    case LogRecord::Type::kImu: {
      const ImuSample& m = record.imu;
      *names = kImuFields;
      const double values[] = {m.t, m.gyro.x(), m.gyro.y(), m.gyro.z(), m.acc.x(), m.acc.y(), m.acc.z()};
      std::copy(std::begin(values), std::end(values), v);
      return 7;
    }
    case LogRecord::Type::kWheel:
      *names = kWheelFields;
      v[0] = record.wheel.t, v[1] = record.wheel.left_pulses, v[2] = record.wheel.right_pulses;
      return 3;
    case LogRecord::Type::kGnss: {
      const GnssRecord& g = record.gnss;
      *names = kGnssFields;
      const double values[] = {g.t, g.lat_deg, g.lon_deg, g.alt_m, g.heading_deg, g.heading_valid ? 1.0 : 0.0,
                               g.sigma_enu.x(), g.sigma_enu.y(), g.sigma_enu.z()};
      std::copy(std::begin(values), std::end(values), v);
      return g.has_sigma ? 9 : 6;
    }
    case LogRecord::Type::kGnssVelocity: {
      const GnssVelocityRecord& g = record.gnss_velocity;
      *names = kGnssVelocityFields;
      const double values[] = {g.t, g.v_enu.x(), g.v_enu.y(), g.v_enu.z(), g.sigma_enu.x(), g.sigma_enu.y(),
                               g.sigma_enu.z()};
      std::copy(std::begin(values), std::end(values), v);
      return g.has_sigma ? 7 : 4;
    }
  }
  return 0;
}

}  // namespace

LineParse CheckLogRecord(LogRecord* record, InputIssue* issue, const ImuRange& range) {
  double v[kMaxNumbers];
  const char* const* names = nullptr;
  const size_t n = RecordValues(*record, v, &names);
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) {
      return Damaged(issue, kNonFinite, "field " + std::to_string(i + 2) + " (" + names[i] + ") is not finite");
    }
  }
  if (CheckValues(record->type, n, v, range, issue) == LineParse::kDamaged) return LineParse::kDamaged;
  FillRecord(v, n, record);  // as a parsed line: the heading normalised, unused fields zero
  return LineParse::kRecord;
}

LineParse ParseLogLine(std::string_view line, LogRecord* record, InputIssue* issue, const ImuRange& range) {
  if (const void* hash = std::memchr(line.data(), '#', line.size())) {
    line = line.substr(0, static_cast<const char*>(hash) - line.data());
  }
  Tokens tokens;
  Tokenize(line, &tokens);
  if (tokens.count == 0) return LineParse::kBlank;

  const char* const* names = nullptr;
  size_t expected = 0;
  if (!ClassifyType(tokens, record, &names, &expected)) {
    return Damaged(issue, kUnknownType,
                   "unknown record type " + QuoteToken(tokens.tok[0]) + " (expected IMU, ODOM, GNSS or GVEL)");
  }
  const size_t n = tokens.count - 1;
  if (CheckFieldCount(record->type, names, n, expected, issue) == LineParse::kDamaged) {
    return LineParse::kDamaged;
  }
  double v[kMaxNumbers];
  if (ParseValues(tokens, record->type, names, n, v, range, issue) == LineParse::kDamaged) return LineParse::kDamaged;
  FillRecord(v, n, record);
  return LineParse::kRecord;
}

}  // namespace gins
