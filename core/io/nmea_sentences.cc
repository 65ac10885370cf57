#include "core/io/nmea_sentences.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/time_scales.h"

namespace gins {
namespace {

constexpr double kKnotsPerMps = 3600.0 / 1852.0;  // the international nautical mile
// Below this ground speed the velocity's direction is noise: RMC leaves the course empty.
constexpr double kMinSpeedForCourse = 0.05;  // m/s

// v with `decimals` digits after the point, rounded once and printed as rounded (so a tie cannot round
// differently in printf), never "-0.000".
std::string Fixed(double v, int decimals) {
  const double scale = std::pow(10.0, decimals);
  double r = std::round(v * scale) / scale;
  if (r == 0.0) r = 0.0;  // drops the sign of -0
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, r);
  return buf;
}

// An azimuth (deg) in [0, 360) with 3 decimals: 359.9996 prints "0.000", not "360.000".
std::string Azimuth(double deg) {
  double a = std::round(std::fmod(deg, 360.0) * 1000.0) / 1000.0;
  if (a < 0.0) a += 360.0;
  if (a >= 360.0) a -= 360.0;
  return Fixed(a, 3);
}

// The epoch on the calendar, rounded once to the 0.01 s the sentences print: the time and RMC's date both
// come from it, so 23:59:59.996 is 00:00:00.00 of the next day. (A multiple of 0.01 s that is a minute
// boundary is an integer, exact in a double, so the calendar cannot fall a hair short of it.)
UtcCalendar RoundedUtc(double unix_utc) { return ToUtcCalendar(std::round(unix_utc * 100.0) / 100.0); }

// hhmmss.ss
std::string TimeField(const UtcCalendar& c) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%02d%02d%05.2f", c.hour, c.minute, c.second);
  return buf;
}

// "ddmm.mmmmmmm,N" (2 degree digits) or "dddmm.mmmmmmm,E" (3): rounded once to whole 1e-7 minutes, so
// 59.99999999' carries into the degree. A value that rounds to zero is N or E.
std::string AngleFields(double deg, int degree_digits, char positive, char negative) {
  constexpr long long kUnitsPerMinute = 10000000;
  constexpr long long kUnitsPerDegree = 60 * kUnitsPerMinute;
  const long long units = std::llround(std::fabs(deg) * static_cast<double>(kUnitsPerDegree));
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%0*lld%02lld.%07lld,%c", degree_digits, units / kUnitsPerDegree,
                units % kUnitsPerDegree / kUnitsPerMinute, units % kUnitsPerMinute,
                deg < 0.0 && units > 0 ? negative : positive);
  return buf;
}

// "lat,N/S,lon,E/W"; the longitude is wrapped to [-180, 180].
std::string PositionFields(const GeoSample& s) {
  return AngleFields(s.lat_deg, 2, 'N', 'S') + "," + AngleFields(std::remainder(s.lon_deg, 360.0), 3, 'E', 'W');
}

bool HasFiniteFix(const NmeaEpoch& e) {
  return std::isfinite(e.unix_utc) && std::isfinite(e.sample.lat_deg) && std::isfinite(e.sample.lon_deg) &&
         std::isfinite(e.sample.height_m);
}

// "$<talker><type>,<fields>*HH\r\n"
std::string Sentence(const NmeaEpoch& e, const char* type, const std::string& fields) {
  const std::string body = e.talker + type + "," + fields;
  return "$" + body + "*" + NmeaChecksum(body) + "\r\n";
}

// RMC's mode indicator (NMEA 2.3): readers of that version know A, D, E, N only, so RTK is D.
char ModeIndicator(NmeaQuality q) {
  switch (q) {
    case NmeaQuality::kDgps:
    case NmeaQuality::kRtkFixed:
    case NmeaQuality::kRtkFloat:
      return 'D';
    case NmeaQuality::kDeadReckoning:
      return 'E';
    case NmeaQuality::kGps:
      break;
  }
  return 'A';
}

}  // namespace

std::string NmeaChecksum(std::string_view body) {
  unsigned char x = 0;
  for (const char ch : body) x ^= static_cast<unsigned char>(ch);
  char buf[3];
  std::snprintf(buf, sizeof(buf), "%02X", x);
  return buf;
}

std::string NmeaGga(const NmeaEpoch& e) {
  if (!HasFiniteFix(e)) return "";
  // time, position, quality, satellites and HDOP (empty), altitude, M, geoid separation, M, age and
  // station (empty).
  return Sentence(e, "GGA",
                  TimeField(RoundedUtc(e.unix_utc)) + "," + PositionFields(e.sample) + "," +
                      std::to_string(static_cast<int>(e.quality)) + ",,," + Fixed(e.sample.height_m, 4) + ",M,0.0,M,,");
}

std::string NmeaRmc(const NmeaEpoch& e) {
  if (!HasFiniteFix(e)) return "";
  const UtcCalendar c = RoundedUtc(e.unix_utc);
  std::string speed, course;
  if (e.sample.v_enu && std::isfinite(e.sample.v_enu->x()) && std::isfinite(e.sample.v_enu->y())) {
    const double east = e.sample.v_enu->x(), north = e.sample.v_enu->y();
    const double ground_speed = std::hypot(east, north);
    speed = Fixed(ground_speed * kKnotsPerMps, 3);
    if (ground_speed >= kMinSpeedForCourse) course = Azimuth(std::atan2(east, north) * kRadToDeg);
  }
  char date[16];
  std::snprintf(date, sizeof(date), "%02d%02d%02d", c.day, c.month, c.year % 100);
  // time, status, position, speed, course, date, magnetic variation and its E/W (empty), mode.
  return Sentence(e, "RMC",
                  TimeField(c) + ",A," + PositionFields(e.sample) + "," + speed + "," + course + "," + date + ",,," +
                      ModeIndicator(e.quality));
}

std::string NmeaGst(const NmeaEpoch& e) {
  if (!HasFiniteFix(e) || !e.sample.sigma_enu || !e.sample.sigma_enu->allFinite()) return "";
  const double east = e.sample.sigma_enu->x(), north = e.sample.sigma_enu->y(), up = e.sample.sigma_enu->z();
  // time, RMS (empty), semi-major, semi-minor, orientation of the semi-major axis, σ latitude, longitude,
  // altitude.
  return Sentence(e, "GST",
                  TimeField(RoundedUtc(e.unix_utc)) + ",," + Fixed(std::max(east, north), 4) + "," +
                      Fixed(std::min(east, north), 4) + "," + (north >= east ? "0.0" : "90.0") + "," + Fixed(north, 4) +
                      "," + Fixed(east, 4) + "," + Fixed(up, 4));
}

std::string NmeaHdt(const NmeaEpoch& e) {
  if (!HasFiniteFix(e) || !e.sample.heading_deg || !std::isfinite(*e.sample.heading_deg)) return "";
  return Sentence(e, "HDT", Azimuth(*e.sample.heading_deg) + ",T");
}

}  // namespace gins
