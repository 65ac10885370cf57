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

template <typename R>
constexpr const RecordTypeInfo& Info() {
  return RecordTraits<R>::kInfo;
}

// The most numbers a line has (GNSS with σ).
constexpr size_t MaxNumbers() {
  size_t most = 0;
  for (const RecordTypeInfo& type : kRecordTypes) most = std::max(most, type.max_fields);
  return most;
}
constexpr size_t kMaxNumbers = MaxNumbers();
constexpr size_t kMaxTokens = kMaxNumbers + 1;  // plus the type

// CheckFieldCount's messages call the optional fields the σ, "all three or none" (one alone cannot be partly
// there).
constexpr bool OptionalFieldsAreSigma() {
  for (const RecordTypeInfo& type : kRecordTypes) {
    const size_t optional = type.max_fields - type.min_fields;
    if (optional != 0 && optional != 1 && optional != 3) return false;
  }
  return true;
}
static_assert(OptionalFieldsAreSigma());

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

// Heading in [-360, 360] -> [0, 360).
double NormaliseHeading(double h) {
  h = std::fmod(h, 360.0);
  if (h < 0.0) h += 360.0;
  if (h >= 360.0 || h == 0.0) h = 0.0;  // -1e-20 + 360 rounds to 360; -0 becomes +0
  return h;
}

// A record type's own part of the line: Absurd, the range checks on its n parsed numbers v (the detail of
// the first absurd field, or empty); Fill, the record from them; Values, the inverse of Fill (the numbers in
// log field order; returns n).
// One specialisation per built-in alternative of LogRecordData; a measurement module's record carries its own
// (core/measurement_module.h).
template <typename R>
struct FieldCodec {
  static std::string Absurd(const double* v, size_t n, const ImuRange& /*range*/) { return R::Absurd(v, n); }
  static void Fill(const double* v, size_t n, R* m) { R::Fill(v, n, m); }
  static size_t Values(const R& m, double* v) { return R::Values(m, v); }
};

template <>
struct FieldCodec<ImuSample> {
  static std::string Absurd(const double* v, size_t /*n*/, const ImuRange& range) {
    const char* const* names = Info<ImuSample>().fields;
    for (size_t i = 1; i <= 3; ++i) {
      if (std::abs(v[i]) > range.max_gyro) {
        return FieldValue(i, names[i], v[i]) + " rad/s, beyond ±" + Num(range.max_gyro) + " (imu.max_gyro_rad_s)";
      }
    }
    for (size_t i = 4; i <= 6; ++i) {
      if (std::abs(v[i]) > range.max_acc) {
        return FieldValue(i, names[i], v[i]) + " m/s², beyond ±" + Num(range.max_acc) + " (imu.max_acc_m_s2)";
      }
    }
    return {};
  }
  static void Fill(const double* v, size_t /*n*/, ImuSample* m) {
    m->t = v[0];
    m->gyro = Vec3(v[1], v[2], v[3]);
    m->acc = Vec3(v[4], v[5], v[6]);
  }
  static size_t Values(const ImuSample& m, double* v) {
    const double values[] = {m.t, m.gyro.x(), m.gyro.y(), m.gyro.z(), m.acc.x(), m.acc.y(), m.acc.z()};
    std::copy(std::begin(values), std::end(values), v);
    return 7;
  }
};

template <>
struct FieldCodec<WheelRecord> {
  static std::string Absurd(const double* v, size_t /*n*/, const ImuRange& /*range*/) {
    for (size_t i = 1; i <= 2; ++i) {
      if (!(std::abs(v[i]) < kMaxAbsPulses)) {
        return FieldValue(i, Info<WheelRecord>().fields[i], v[i]) + ", |pulses| must be < " + Num(kMaxAbsPulses);
      }
    }
    return {};
  }
  static void Fill(const double* v, size_t /*n*/, WheelRecord* m) {
    m->t = v[0];
    m->left_pulses = v[1];
    m->right_pulses = v[2];
  }
  static size_t Values(const WheelRecord& m, double* v) {
    v[0] = m.t, v[1] = m.left_pulses, v[2] = m.right_pulses;
    return 3;
  }
};

template <>
struct FieldCodec<GnssRecord> {
  static std::string Absurd(const double* v, size_t n, const ImuRange& /*range*/) {
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
        return FieldValue(i, Info<GnssRecord>().fields[i], v[i]) + " m, σ must be in (0, " + Num(kMaxSigma) + ")";
      }
    }
    return {};
  }
  static void Fill(const double* v, size_t n, GnssRecord* g) {
    g->t = v[0];
    g->lat_deg = v[1];
    g->lon_deg = v[2];
    g->alt_m = v[3];
    g->heading_valid = v[5] == 1.0;
    g->heading_deg = g->heading_valid ? NormaliseHeading(v[4]) : 0.0;
    g->has_sigma = n == 9;
    g->sigma_enu = g->has_sigma ? Vec3(v[6], v[7], v[8]) : Vec3::Zero();
  }
  static size_t Values(const GnssRecord& g, double* v) {
    const double values[] = {g.t, g.lat_deg, g.lon_deg, g.alt_m, g.heading_deg, g.heading_valid ? 1.0 : 0.0,
                             g.sigma_enu.x(), g.sigma_enu.y(), g.sigma_enu.z()};
    std::copy(std::begin(values), std::end(values), v);
    return g.has_sigma ? 9 : 6;
  }
};

template <>
struct FieldCodec<GnssVelocityRecord> {
  static std::string Absurd(const double* v, size_t n, const ImuRange& /*range*/) {
    const char* const* names = Info<GnssVelocityRecord>().fields;
    for (size_t i = 1; i <= 3; ++i) {
      if (!(std::abs(v[i]) <= log_limits::kMaxAbsSpeed)) {
        return FieldValue(i, names[i], v[i]) + " m/s, beyond ±" + Num(log_limits::kMaxAbsSpeed);
      }
    }
    for (size_t i = 4; i < n; ++i) {
      if (!(v[i] > 0.0 && v[i] < log_limits::kMaxAbsSpeed)) {
        return FieldValue(i, names[i], v[i]) + " m/s, σ must be in (0, " + Num(log_limits::kMaxAbsSpeed) + ")";
      }
    }
    return {};
  }
  static void Fill(const double* v, size_t n, GnssVelocityRecord* g) {
    g->t = v[0];
    g->v_enu = Vec3(v[1], v[2], v[3]);
    g->has_sigma = n == 7;
    g->sigma_enu = g->has_sigma ? Vec3(v[4], v[5], v[6]) : Vec3::Zero();
  }
  static size_t Values(const GnssVelocityRecord& g, double* v) {
    const double values[] = {g.t, g.v_enu.x(), g.v_enu.y(), g.v_enu.z(), g.sigma_enu.x(), g.sigma_enu.y(),
                             g.sigma_enu.z()};
    std::copy(std::begin(values), std::end(values), v);
    return g.has_sigma ? 7 : 4;
  }
};

// Field counts are of the values after the type; the message lists what the type needs.
LineParse CheckFieldCount(const RecordTypeInfo& type, size_t n, InputIssue* issue) {
  // The optional σ columns come all or none.
  const bool optional = type.min_fields != type.max_fields;
  if (optional && n > type.min_fields && n < type.max_fields) {
    std::string detail = std::string(type.token) + " has " + std::to_string(n) + " values;";
    for (size_t i = type.min_fields; i < type.max_fields; ++i) detail += std::string(" ") + type.fields[i];
    return Damaged(issue, kMissingFields, detail + " come all three or none");
  }
  const size_t expected = optional && n < type.max_fields ? type.min_fields : type.max_fields;
  if (n != expected) {
    std::string detail = std::string(type.token) + " has " + std::to_string(n) + " values, needs " +
                         (optional ? std::to_string(type.min_fields) + " or " + std::to_string(type.max_fields)
                                   : std::to_string(expected)) +
                         ":";
    for (size_t i = 0; i < type.max_fields; ++i) detail += std::string(" ") + type.fields[i];
    if (optional) detail += " (sigma optional)";
    return Damaged(issue, n < expected ? kMissingFields : kExtraFields, std::move(detail));
  }
  return LineParse::kRecord;
}

// Range checks of a record's n finite numbers v (in log field order): one rule for parsed lines and for
// records pushed through the API.
template <typename R>
LineParse CheckValues(size_t n, const double* v, const ImuRange& range, InputIssue* issue) {
  if (!(v[0] > 0.0)) return Damaged(issue, kAbsurdValue, FieldValue(0, "t", v[0]) + ", time must be > 0");
  if (!(v[0] < log_limits::kMaxTime)) {
    return Damaged(issue, kAbsurdValue,
                   FieldValue(0, "t", v[0]) + " s, beyond " + Num(log_limits::kMaxTime) + " s (not seconds?)");
  }
  std::string absurd = FieldCodec<R>::Absurd(v, n, range);
  if (!absurd.empty()) return Damaged(issue, kAbsurdValue, std::move(absurd));
  return LineParse::kRecord;
}

// Parses the n numbers after the type into v.
LineParse ParseNumbers(const Tokens& tokens, const char* const* names, size_t n, double* v, InputIssue* issue) {
  for (size_t i = 0; i < n; ++i) {
    const NumberStatus status = ParseNumber(tokens.tok[i + 1], &v[i]);
    if (status == NumberStatus::kOk) continue;
    const std::string field =
        "field " + std::to_string(i + 2) + " (" + names[i] + ") " + QuoteToken(tokens.tok[i + 1]);
    if (status == NumberStatus::kBad) return Damaged(issue, kBadNumber, field + " is not a number");
    return Damaged(issue, kNonFinite, field + " is not finite");
  }
  return LineParse::kRecord;
}

// The line's values as a record of type R, its token already matched.
template <typename R>
LineParse ParseAs(const Tokens& tokens, LogRecord* record, InputIssue* issue, const ImuRange& range) {
  const size_t n = tokens.count - 1;
  if (CheckFieldCount(Info<R>(), n, issue) == LineParse::kDamaged) return LineParse::kDamaged;
  double v[kMaxNumbers];
  if (ParseNumbers(tokens, Info<R>().fields, n, v, issue) == LineParse::kDamaged) return LineParse::kDamaged;
  if (CheckValues<R>(n, v, range, issue) == LineParse::kDamaged) return LineParse::kDamaged;
  FieldCodec<R>::Fill(v, n, &record->data.emplace<R>());
  return LineParse::kRecord;
}

using LineParser = LineParse (*)(const Tokens&, LogRecord*, InputIssue*, const ImuRange&);
template <typename Variant>
struct LineParsers;
template <typename... R>
struct LineParsers<std::variant<R...>> {
  static constexpr LineParser kByIndex[] = {&ParseAs<R>...};  // by LogRecordData's index, as kRecordTypes
};

// "IMU, ODOM, GNSS or GVEL".
std::string TokenList() {
  std::string list;
  for (size_t k = 0; k < kNumRecordTypes; ++k) {
    list += (k == 0 ? "" : k + 1 < kNumRecordTypes ? ", " : " or ") + std::string(kRecordTypes[k].token);
  }
  return list;
}

// The checks of a record that did not come from a line, as ParseAs's on its numbers.
template <typename R>
LineParse CheckRecord(R* m, InputIssue* issue, const ImuRange& range) {
  double v[kMaxNumbers];
  const size_t n = FieldCodec<R>::Values(*m, v);
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) {
      return Damaged(issue, kNonFinite,
                     "field " + std::to_string(i + 2) + " (" + Info<R>().fields[i] + ") is not finite");
    }
  }
  if (CheckValues<R>(n, v, range, issue) == LineParse::kDamaged) return LineParse::kDamaged;
  FieldCodec<R>::Fill(v, n, m);  // as a parsed line: the heading normalised, unused fields zero
  return LineParse::kRecord;
}

}  // namespace

LineParse CheckLogRecord(LogRecord* record, InputIssue* issue, const ImuRange& range) {
  return std::visit([&](auto& m) { return CheckRecord(&m, issue, range); }, record->data);
}

LineParse ParseLogLine(std::string_view line, LogRecord* record, InputIssue* issue, const ImuRange& range) {
  if (const void* hash = std::memchr(line.data(), '#', line.size())) {
    line = line.substr(0, static_cast<const char*>(hash) - line.data());
  }
  Tokens tokens;
  Tokenize(line, &tokens);
  if (tokens.count == 0) return LineParse::kBlank;

  for (size_t k = 0; k < kNumRecordTypes; ++k) {
    if (tokens.tok[0] == kRecordTypes[k].token) {
      return LineParsers<LogRecordData>::kByIndex[k](tokens, record, issue, range);
    }
  }
  return Damaged(issue, kUnknownType,
                 "unknown record type " + QuoteToken(tokens.tok[0]) + " (expected " + TokenList() + ")");
}

}  // namespace gins
