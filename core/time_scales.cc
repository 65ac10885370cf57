#include "core/time_scales.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gins {
namespace {

// Unix UTC of 00:00:00 on the day from which GPS − UTC is the index + 1 (IERS Bulletin C).
constexpr double kLeapDays[] = {
    362793600.0,   // 1981-07-01
    394329600.0,   // 1982-07-01
    425865600.0,   // 1983-07-01
    489024000.0,   // 1985-07-01
    567993600.0,   // 1988-01-01
    631152000.0,   // 1990-01-01
    662688000.0,   // 1991-01-01
    709948800.0,   // 1992-07-01
    741484800.0,   // 1993-07-01
    773020800.0,   // 1994-07-01
    820454400.0,   // 1996-01-01
    867715200.0,   // 1997-07-01
    915148800.0,   // 1999-01-01
    1136073600.0,  // 2006-01-01
    1230768000.0,  // 2009-01-01
    1341100800.0,  // 2012-07-01
    1435708800.0,  // 2015-07-01
    1483228800.0,  // 2017-01-01
};
constexpr int kLeaps = sizeof(kLeapDays) / sizeof(kLeapDays[0]);

}  // namespace

int64_t DaysFromCivil(int y, int m, int d) {
  y -= m <= 2;
  const int64_t era = (y >= 0 ? y : y - 399) / 400;
  const int64_t yoe = y - era * 400;
  const int64_t doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

void CivilFromDays(int64_t z, int* y, int* m, int* d) {
  z += 719468;
  const int64_t era = (z >= 0 ? z : z - 146096) / 146097;
  const int64_t doe = z - era * 146097;
  const int64_t yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const int64_t mp = (5 * doy + 2) / 153;
  *d = static_cast<int>(doy - (153 * mp + 2) / 5 + 1);
  *m = static_cast<int>(mp < 10 ? mp + 3 : mp - 9);
  *y = static_cast<int>(yoe + era * 400 + (*m <= 2));
}

bool ParseLogTimeScale(const std::string& name, LogTimeScale* scale) {
  if (name == "gps") {
    *scale = LogTimeScale::kGps;
  } else if (name == "unix") {
    *scale = LogTimeScale::kUnixUtc;
  } else {
    return false;
  }
  return true;
}

const char* LogTimeScaleName(LogTimeScale scale) { return scale == LogTimeScale::kGps ? "gps" : "unix"; }

int GpsMinusUtc(double unix_utc) {
  int n = 0;
  while (n < kLeaps && unix_utc >= kLeapDays[n]) ++n;
  return n;
}

double GpsToUnixUtc(double t_gps) {
  const double unix_gps = t_gps + kGpsEpochUnix;  // a Unix-style count on GPS time
  // Leap second k + 1 is inserted before kLeapDays[k] UTC, where GPS time reads kLeapDays[k] + k .. + k + 1:
  // from its start GPS − UTC counts it, so that second reads 23:59:59 again.
  int n = 0;
  while (n < kLeaps && unix_gps >= kLeapDays[n] + n) ++n;
  return unix_gps - n;
}

double UnixUtcToGps(double unix_utc) { return unix_utc + GpsMinusUtc(unix_utc) - kGpsEpochUnix; }

double LogTimeToUnixUtc(double t, LogTimeScale scale) {
  return scale == LogTimeScale::kGps ? GpsToUnixUtc(t) : t;
}

double UnixUtcToLogTime(double unix_utc, LogTimeScale scale) {
  return scale == LogTimeScale::kGps ? UnixUtcToGps(unix_utc) : unix_utc;
}

UtcCalendar ToUtcCalendar(double unix_utc) {
  // In range of the day count's integer (a NaN to the epoch): no cast of an out-of-range double.
  unix_utc = unix_utc == unix_utc ? std::min(std::max(unix_utc, -1e15), 1e15) : 0.0;
  const double days = std::floor(unix_utc / 86400.0);
  double sod = unix_utc - days * 86400.0;
  UtcCalendar c;
  CivilFromDays(static_cast<int64_t>(days), &c.year, &c.month, &c.day);
  c.hour = static_cast<int>(sod / 3600.0);
  sod -= c.hour * 3600.0;
  c.minute = static_cast<int>(sod / 60.0);
  c.second = sod - c.minute * 60.0;
  return c;
}

double FromUtcCalendar(const UtcCalendar& c) {
  return static_cast<double>(DaysFromCivil(c.year, c.month, c.day)) * 86400.0 + c.hour * 3600.0 + c.minute * 60.0 +
         c.second;
}

std::string IsoUtc(double unix_utc, int decimals) {
  // Rounded first, so that 59.9999 s does not print as "60.000".
  const double scale = std::pow(10.0, decimals);
  const UtcCalendar c = ToUtcCalendar(std::round(unix_utc * scale) / scale);
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%04d-%02d-%02dT%02d:%02d:%0*.*fZ", c.year, c.month, c.day, c.hour, c.minute,
                decimals > 0 ? decimals + 3 : 2, decimals, c.second);
  return buf;
}

}  // namespace gins
