// One NMEA 0183 sentence checked and parsed into its values, without state: the epochs, dates and records
// are the reader's (nmea_reader.cc, core/io/gnss_formats.h). Exposed for it and its tests.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/conventions.h"
#include "core/io/gnss_formats.h"

namespace gins {

struct NmeaSentence {
  enum class Type { kIgnored, kGga, kRmc, kGst, kVtg, kHeading, kZda };
  Type type = Type::kIgnored;
  std::string ignored;      // kIgnored: what it is, for the count ("sentence GSV", "GGA without a time")
  std::string_view prefix;  // text before the '$' (a logger's stamp), usually empty
  bool timed = false;       // GGA, RMC, GST, ZDA with a time of day
  int64_t sod = 0;          // UTC seconds of the day (86400 during 23:59:60)
  double frac = 0.0;
  bool leap_second = false;
  // GGA: the quality digit, and where it is a measurement the position and HDOP.
  int quality = -1;
  double lat = 0.0, lon = 0.0, height = 0.0;  // height: altitude + geoid separation (ellipsoidal)
  bool has_separation = false;
  double hdop = -1.0;  // < 0: none
  // RMC, ZDA: the date.
  bool has_date = false;
  int64_t days = 0;  // since 1980-01-06
  // RMC, VTG: the speed and course over ground as a horizontal velocity (valid only).
  bool has_velocity = false;
  double speed = 0.0;  // m/s
  Vec3 v_enu = Vec3::Zero();
  // GST: σ east, north, up (m).
  bool has_sigma = false;
  Vec3 sigma_enu = Vec3::Zero();
  // HDT, THS: the true heading (deg).
  bool has_heading = false;
  double heading = 0.0;
};

// GGA's fix quality digit as a solution class: 1, 3 (PPS) single, 2 dgps, 4 fix, 5 float, 9 sbas (NovAtel's
// WAAS). False for the entries that are no measurement, *dropped saying which: 0 no fix, 6 dead reckoning,
// 7 manual input, 8 simulator.
bool GgaQuality(int digit, FixQuality* quality, const char** dropped);

class NmeaParser {
 public:
  // The sentence on a line (from its first '$'; checksum required): nullptr with *s filled, or the damage
  // reason (bad_checksum, truncated, not_nmea, bad_time, unknown_quality, ...) with *detail.
  const char* Parse(std::string_view line, NmeaSentence* s, std::string* detail);

 private:
  const char* Fields(NmeaSentence* s, std::string* detail);
  const char* Gga(NmeaSentence* s, std::string* detail);
  const char* Rmc(NmeaSentence* s, std::string* detail);
  const char* Gst(NmeaSentence* s, std::string* detail);
  const char* Vtg(NmeaSentence* s, std::string* detail);
  const char* Heading(NmeaSentence* s, std::string* detail);
  const char* Zda(NmeaSentence* s, std::string* detail);
  const char* Count(size_t needed, const char* sentence, const char* has, std::string* detail) const;
  const char* Time(NmeaSentence* s, std::string* detail) const;
  const char* Number(size_t index, const char* name, double* v, std::string* detail) const;
  const char* Coordinate(size_t index, bool latitude, double* deg, std::string* detail) const;
  const char* Speed(size_t speed, double unit, size_t course, NmeaSentence* s, std::string* detail) const;

  std::vector<std::string_view> f_;  // the fields, f_[0] the address ("GPGGA")
};

}  // namespace gins
