#include "core/io/nmea_parse.h"

#include <cctype>
#include <cmath>

#include "core/io/nmea_sentences.h"  // NmeaChecksum: the writer's, so reading and writing agree

namespace gins {
namespace {

using gnss_reason::kBadChecksum;
using gnss_reason::kBadTime;
using gnss_reason::kNotNmea;
using gnss_reason::kUnknownQuality;
using input_reason::kAbsurdValue;
using input_reason::kBadNumber;
using input_reason::kExtraFields;
using input_reason::kMissingFields;
using input_reason::kNonFinite;
using input_reason::kTruncated;

constexpr double kKnot = 1852.0 / 3600.0;  // m/s
constexpr double kKmh = 1.0 / 3.6;         // m/s
// Below this speed the course is noise and may be empty: the velocity is then about zero whatever it is.
constexpr double kMinSpeedForCourse = 0.05;  // m/s
// A GST σ printed as 0 (below its resolution) is floored to this, m: a zero σ would break a solver.
constexpr double kMinSigma = 1e-3;

bool IsHex(char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; }

// The mode indicator of RMC and VTG (NMEA 2.3+): estimated, manual, simulated and not valid carry no
// measured velocity; an empty field (older receivers) is fine.
bool ValidMode(std::string_view mode) {
  return mode.empty() || std::string_view("ENMS").find(mode[0]) == std::string_view::npos;
}

}  // namespace

bool GgaQuality(int digit, FixQuality* quality, const char** dropped) {
  switch (digit) {
    case 1:
    case 3:
      *quality = FixQuality::kSingle;
      return true;
    case 2:
      *quality = FixQuality::kDgps;
      return true;
    case 4:
      *quality = FixQuality::kFix;
      return true;
    case 5:
      *quality = FixQuality::kFloat;
      return true;
    case 9:
      *quality = FixQuality::kSbas;
      return true;
    case 0:
      *dropped = "no fix (GGA quality 0)";
      return false;
    case 6:
      *dropped = "dead reckoning (GGA quality 6)";
      return false;
    case 7:
      *dropped = "manual input (GGA quality 7)";
      return false;
    default:
      *dropped = "simulator (GGA quality 8)";
      return false;
  }
}

const char* NmeaParser::Parse(std::string_view text, NmeaSentence* s, std::string* detail) {
  *s = NmeaSentence();
  const size_t start = text.find('$');
  if (start == std::string_view::npos) {
    *detail = "no '$' sentence on the line: " + QuoteToken(text);
    return kNotNmea;
  }
  s->prefix = text.substr(0, start);
  const size_t star = text.find('*', start);
  if (star == std::string_view::npos || star + 3 > text.size()) {
    *detail = "no '*HH' checksum at the end: the sentence is cut";
    return kTruncated;
  }
  const std::string_view body = text.substr(start + 1, star - start - 1), given = text.substr(star + 1, 2);
  if (text.substr(star + 3).find_first_not_of(" \t") != std::string_view::npos) {
    *detail = "text after the checksum: " + QuoteToken(text.substr(star + 3));
    return kExtraFields;
  }
  const std::string want = NmeaChecksum(body);
  if (!IsHex(given[0]) || !IsHex(given[1]) || std::toupper(given[0]) != want[0] || std::toupper(given[1]) != want[1]) {
    *detail = "checksum " + QuoteToken(given) + ", the sentence's is " + want;
    return kBadChecksum;
  }
  SplitFields(body, FieldSplit::kExact, ',', &f_);
  const std::string_view address = f_[0];
  if (address.size() != 5 || address[0] == 'P') {  // proprietary ($PUBX, $PASHR, ...) or not NMEA 0183
    s->ignored = "sentence " + std::string(address.substr(0, 8));
    return nullptr;
  }
  return Fields(s, detail);
}

const char* NmeaParser::Fields(NmeaSentence* s, std::string* detail) {
  const std::string_view type = f_[0].substr(2);  // after the talker: GP, GN, GL, GA, GB, ... alike
  if (type == "GGA") return Gga(s, detail);
  if (type == "RMC") return Rmc(s, detail);
  if (type == "GST") return Gst(s, detail);
  if (type == "VTG") return Vtg(s, detail);
  if (type == "HDT" || type == "THS") return Heading(s, detail);
  if (type == "ZDA") return Zda(s, detail);
  s->ignored = "sentence " + std::string(type);
  return nullptr;
}

const char* NmeaParser::Count(size_t needed, const char* sentence, const char* has, std::string* detail) const {
  if (f_.size() >= needed + 1) return nullptr;
  *detail = FormatText("%s with %zu fields, it has %s", sentence, f_.size() - 1, has);
  return kMissingFields;
}

// Field 1, the time of day; a sentence without one (a receiver before its first fix) is ignored.
const char* NmeaParser::Time(NmeaSentence* s, std::string* detail) const {
  if (f_[1].empty()) {
    s->ignored = std::string(f_[0].substr(2)) + " without a time";
    return nullptr;
  }
  if (!ParseNmeaTimeOfDay(f_[1], &s->sod, &s->frac, &s->leap_second)) {
    *detail = "time " + QuoteToken(f_[1]) + " is not hhmmss.ss";
    return kBadTime;
  }
  s->timed = true;
  return nullptr;
}

const char* NmeaParser::Number(size_t index, const char* name, double* v, std::string* detail) const {
  const NumberStatus status = ParseNumber(f_[index], v);
  if (status == NumberStatus::kOk) return nullptr;
  *detail = FormatText("field %zu (%s) %s is %s", index, name, QuoteToken(f_[index]).c_str(),
                       f_[index].empty()              ? "empty"
                       : status == NumberStatus::kBad ? "not a number"
                                                      : "not finite");
  return f_[index].empty() ? kMissingFields : status == NumberStatus::kBad ? kBadNumber : kNonFinite;
}

// ddmm.mmmm / dddmm.mmmm and its hemisphere: degrees and minutes split in the text (the two digits before
// the point are minutes), so that no division by 100 rounds them.
const char* NmeaParser::Coordinate(size_t index, bool latitude, double* deg, std::string* detail) const {
  const std::string_view text = f_[index], hemisphere = f_[index + 1];
  const size_t dot = std::min(text.find('.'), text.size());
  double degrees = 0.0, minutes = 0.0;
  const std::string_view positive = latitude ? "N" : "E", negative = latitude ? "S" : "W";
  if (dot < 3 || dot > (latitude ? 4u : 5u) || !std::isdigit(static_cast<unsigned char>(text[0])) ||
      !std::isdigit(static_cast<unsigned char>(text[dot - 2])) ||
      ParseNumber(text.substr(0, dot - 2), &degrees) != NumberStatus::kOk ||
      ParseNumber(text.substr(dot - 2), &minutes) != NumberStatus::kOk || !(minutes < 60.0) ||
      (hemisphere != positive && hemisphere != negative)) {
    *detail = FormatText("field %zu (%s) %s %s is not %s", index, latitude ? "latitude" : "longitude",
                         QuoteToken(text).c_str(), QuoteToken(hemisphere).c_str(),
                         latitude ? "ddmm.mmmm N|S" : "dddmm.mmmm E|W");
    return text.empty() ? kMissingFields : kBadNumber;
  }
  *deg = (hemisphere == negative ? -1.0 : 1.0) * (degrees + minutes / 60.0);
  return nullptr;
}

const char* NmeaParser::Gga(NmeaSentence* s, std::string* detail) {
  if (const char* reason = Count(9, "GGA", "14 (time to altitude needed)", detail)) return reason;
  if (const char* reason = Time(s, detail); reason != nullptr || !s->timed) return reason;
  if (f_[6].size() != 1 || !std::isdigit(static_cast<unsigned char>(f_[6][0]))) {
    *detail = "fix quality " + QuoteToken(f_[6]) + " is not 0-9 (0 none, 1 GPS, 2 DGPS, 4 RTK fixed, 5 float, ...)";
    return kUnknownQuality;
  }
  s->type = NmeaSentence::Type::kGga;
  s->quality = f_[6][0] - '0';
  FixQuality quality;
  const char* no_measurement = nullptr;
  if (!GgaQuality(s->quality, &quality, &no_measurement)) return nullptr;  // its position may be empty
  double alt = 0.0, separation = 0.0;
  const char* reason = Coordinate(2, true, &s->lat, detail);
  if (reason == nullptr) reason = Coordinate(4, false, &s->lon, detail);
  if (reason == nullptr) reason = Number(9, "altitude", &alt, detail);
  if (reason != nullptr) return reason;
  s->has_separation = f_.size() > 11 && !f_[11].empty();
  if (s->has_separation) {
    if (const char* reason = Number(11, "geoid separation", &separation, detail)) return reason;
  }
  s->height = alt + separation;  // the altitude is above the geoid; the separation is the geoid's height
  if (!f_[8].empty()) return Number(8, "HDOP", &s->hdop, detail);
  return nullptr;
}

// Speed (field `speed`, in `unit` m/s) and course over ground (true, deg) as an ENU velocity.
const char* NmeaParser::Speed(size_t speed, double unit, size_t course, NmeaSentence* s, std::string* detail) const {
  double v = 0.0, c = 0.0;
  if (const char* reason = Number(speed, "speed", &v, detail)) return reason;
  if (v < 0.0) {
    *detail = FormatText("field %zu (speed) %g is negative", speed, v);
    return kAbsurdValue;
  }
  v *= unit;
  if (f_[course].empty() && v >= kMinSpeedForCourse) return nullptr;  // moving, but no direction
  if (!f_[course].empty()) {
    if (const char* reason = Number(course, "course", &c, detail)) return reason;
  }
  s->has_velocity = true;
  s->speed = v;
  s->v_enu = Vec3(v * std::sin(c * kDegToRad), v * std::cos(c * kDegToRad), 0.0);
  return nullptr;
}

const char* NmeaParser::Rmc(NmeaSentence* s, std::string* detail) {
  if (const char* reason = Count(9, "RMC", "12 or more (time to date needed)", detail)) return reason;
  if (const char* reason = Time(s, detail); reason != nullptr || !s->timed) return reason;
  s->type = NmeaSentence::Type::kRmc;
  s->has_date = !f_[9].empty();
  if (s->has_date && !ParseNmeaDate(f_[9], &s->days)) {
    *detail = "date " + QuoteToken(f_[9]) + " is not ddmmyy";
    return kBadTime;
  }
  const bool valid = f_[2] == "A" && ValidMode(f_.size() > 12 ? f_[12] : std::string_view());
  return valid && !f_[7].empty() ? Speed(7, kKnot, 8, s, detail) : nullptr;
}

const char* NmeaParser::Gst(NmeaSentence* s, std::string* detail) {
  if (const char* reason = Count(8, "GST", "8", detail)) return reason;
  if (const char* reason = Time(s, detail); reason != nullptr || !s->timed) return reason;
  s->type = NmeaSentence::Type::kGst;
  if (f_[6].empty() || f_[7].empty() || f_[8].empty()) return nullptr;
  double s_lat = 0, s_lon = 0, s_alt = 0;
  const char* reason = Number(6, "σ latitude", &s_lat, detail);
  if (reason == nullptr) reason = Number(7, "σ longitude", &s_lon, detail);
  if (reason == nullptr) reason = Number(8, "σ altitude", &s_alt, detail);
  if (reason != nullptr) return reason;
  if (s_lat < 0 || s_lon < 0 || s_alt < 0) {
    *detail = FormatText("negative σ %g %g %g m", s_lat, s_lon, s_alt);
    return kAbsurdValue;
  }
  s->has_sigma = true;
  s->sigma_enu = Vec3(std::max(s_lon, kMinSigma), std::max(s_lat, kMinSigma), std::max(s_alt, kMinSigma));
  return nullptr;
}

const char* NmeaParser::Vtg(NmeaSentence* s, std::string* detail) {
  if (const char* reason = Count(8, "VTG", "8 or 9", detail)) return reason;
  s->type = NmeaSentence::Type::kVtg;
  if (!ValidMode(f_.size() > 9 ? f_[9] : std::string_view())) return nullptr;
  if (!f_[7].empty()) return Speed(7, kKmh, 1, s, detail);  // km/h: the finer of its two speeds
  return f_[5].empty() ? nullptr : Speed(5, kKnot, 1, s, detail);
}

const char* NmeaParser::Heading(NmeaSentence* s, std::string* detail) {
  if (const char* reason = Count(2, f_[0].substr(2) == "HDT" ? "HDT" : "THS", "2", detail)) return reason;
  s->type = NmeaSentence::Type::kHeading;
  // THS's mode: only A (autonomous) is a measured heading.
  if (f_[1].empty() || (f_[0].substr(2) == "THS" && f_[2] != "A")) return nullptr;
  s->has_heading = true;
  return Number(1, "heading", &s->heading, detail);
}

const char* NmeaParser::Zda(NmeaSentence* s, std::string* detail) {
  if (const char* reason = Count(4, "ZDA", "6", detail)) return reason;
  if (const char* reason = Time(s, detail); reason != nullptr || !s->timed) return reason;
  s->type = NmeaSentence::Type::kZda;
  if (f_[4].empty()) return nullptr;
  double d = 0, m = 0, y = 0;
  s->has_date = ParseNumber(f_[2], &d) == NumberStatus::kOk && ParseNumber(f_[3], &m) == NumberStatus::kOk &&
                ParseNumber(f_[4], &y) == NumberStatus::kOk && d == std::floor(d) && m == std::floor(m) &&
                y == std::floor(y) && std::abs(d) < 100 && std::abs(m) < 100 && std::abs(y) < 1e4 &&
                CalendarDays(static_cast<int>(y), static_cast<int>(m), static_cast<int>(d), &s->days);
  if (s->has_date) return nullptr;
  *detail = "date " + QuoteToken(f_[2]) + " " + QuoteToken(f_[3]) + " " + QuoteToken(f_[4]) + " is not dd mm yyyy";
  return kBadTime;
}

}  // namespace gins
