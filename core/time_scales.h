// The log's clock against civil time, for the formats that carry a date (NMEA, GPX, KML): GPS time and UTC
// differ by the leap seconds (18 s since 2017-01-01), and a log's absolute times are on one of two scales
// (docs/formats.md §2.6).
#pragma once

#include <cstdint>

#include <string>

namespace gins {

// What a log's absolute time stamps count.
enum class LogTimeScale {
  kGps,      // seconds since 1980-01-06 00:00:00 on GPS time (RTKLIB, receivers, the shared real logs)
  kUnixUtc,  // seconds since 1970-01-01 00:00:00 UTC, leap seconds not counted (ROS, PC loggers)
};

// "gps" or "unix"; false for anything else.
bool ParseLogTimeScale(const std::string& name, LogTimeScale* scale);
const char* LogTimeScaleName(LogTimeScale scale);

// The Unix time of the GPS epoch, 1980-01-06 00:00:00 UTC.
inline constexpr double kGpsEpochUnix = 315964800.0;

// GPS − UTC in whole seconds at a UTC instant (Unix time): 0 before 1981-07-01, 18 from 2017-01-01 on (the
// IERS Bulletin C table; no leap second has been announced since).
int GpsMinusUtc(double unix_utc);
// GPS seconds since its epoch <-> Unix UTC, with the leap seconds of that instant. During an inserted leap
// second (23:59:60 UTC) UTC repeats a second; GpsToUnixUtc maps that GPS second onto 23:59:59.
double GpsToUnixUtc(double t_gps);
double UnixUtcToGps(double unix_utc);
// A log time stamp on its scale as Unix UTC.
double LogTimeToUnixUtc(double t, LogTimeScale scale);
double UnixUtcToLogTime(double unix_utc, LogTimeScale scale);

// Days since 1970-01-01 of a proleptic Gregorian date, and back (H. Hinnant's algorithms, exact for any
// year).
int64_t DaysFromCivil(int year, int month, int day);
void CivilFromDays(int64_t days, int* year, int* month, int* day);
// A Unix UTC time as a calendar date and time of day (proleptic Gregorian); times beyond ±1e15 s (30 million
// years) are taken at that bound.
struct UtcCalendar {
  int year = 1970, month = 1, day = 1;  // month 1-12, day 1-31
  int hour = 0, minute = 0;
  double second = 0.0;  // [0, 60)
};
UtcCalendar ToUtcCalendar(double unix_utc);
// The inverse: seconds since 1970-01-01 UTC of a calendar date and time.
double FromUtcCalendar(const UtcCalendar& c);
// ISO 8601 with the given decimals of a second and a Z: "2024-06-01T00:00:00.000Z".
std::string IsoUtc(double unix_utc, int decimals);

// Time stamps below this (about 1983 on either scale) are not absolute: a log on a relative clock (seconds
// since power-on, GPS seconds of the week) has no date to write.
inline constexpr double kMinAbsoluteTime = 1.0e8;
// Nor a time stamp at or beyond the log's own limit (docs/formats.md §2.6: below 1e10 s, the year 2286).
inline constexpr double kMaxAbsoluteTime = 1.0e10;
// A time with a date to write: in [kMinAbsoluteTime, kMaxAbsoluteTime).
inline bool HasDate(double t) { return t >= kMinAbsoluteTime && t < kMaxAbsoluteTime; }

}  // namespace gins
