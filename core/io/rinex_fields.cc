// What both RINEX readers (core/io/rinex.h) share: satellite ids, time systems and RINEX times as GPS
// seconds, and the fields of a fixed-column line.
#include <cmath>
#include <cstdio>

#include "core/io/rinex.h"

namespace gins {

using rinex_internal::Trim;

namespace rinex_internal {

std::string_view Column(std::string_view line, size_t first, size_t width) {
  if (first == 0 || first > line.size()) return {};
  return line.substr(first - 1, width);
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

bool IsBlank(std::string_view s) { return Trim(s).empty(); }

bool ParseInt(std::string_view field, int* value) {
  field = Trim(field);
  bool negative = false;
  if (!field.empty() && (field.front() == '-' || field.front() == '+')) {
    negative = field.front() == '-';
    field.remove_prefix(1);
  }
  if (field.empty() || field.size() > 9) return false;  // 9 digits cannot overflow an int
  int v = 0;
  for (const char ch : field) {
    if (ch < '0' || ch > '9') return false;
    v = v * 10 + (ch - '0');
  }
  *value = negative ? -v : v;
  return true;
}

bool ParseCalendarFields(std::string_view year, std::string_view month, std::string_view day, std::string_view hour,
                         std::string_view minute, std::string_view second, RinexCalendar* c) {
  bool blank = false;
  return ParseInt(year, &c->year) && ParseInt(month, &c->month) && ParseInt(day, &c->day) &&
         ParseInt(hour, &c->hour) && ParseInt(minute, &c->minute) &&
         ParseRinexNumber(second, &c->second, &blank) == NumberStatus::kOk && !blank;
}

}  // namespace rinex_internal

bool ParseGnssSystem(char letter, GnssSystem* system) {
  switch (letter) {
    case 'G': case 'R': case 'E': case 'C': case 'J': case 'S': case 'I':
      *system = static_cast<GnssSystem>(letter);
      return true;
    default:
      return false;
  }
}

bool ParseSatelliteId(std::string_view text, SatelliteId* id) {
  if (text.size() != 3 || !ParseGnssSystem(text[0], &id->system)) return false;
  const char tens = text[1] == ' ' ? '0' : text[1];  // "G 5": RINEX 2 writers pad with a blank
  if (tens < '0' || tens > '9' || text[2] < '0' || text[2] > '9') return false;
  id->prn = (tens - '0') * 10 + (text[2] - '0');
  return id->prn > 0;
}

bool ParseRinexTimeSystem(std::string_view text, RinexTimeSystem* system) {
  static constexpr struct {
    const char* name;
    RinexTimeSystem system;
  } kNames[] = {{"GPS", RinexTimeSystem::kGps},     {"GAL", RinexTimeSystem::kGalileo},
                {"BDT", RinexTimeSystem::kBeidou},  {"QZS", RinexTimeSystem::kQzss},
                {"IRN", RinexTimeSystem::kIrnss},   {"GLO", RinexTimeSystem::kGlonass},
                {"UTC", RinexTimeSystem::kUtc}};
  for (const auto& n : kNames) {
    if (text == n.name) {
      *system = n.system;
      return true;
    }
  }
  return false;
}

const char* RinexTimeSystemName(RinexTimeSystem system) {
  switch (system) {
    case RinexTimeSystem::kGps: return "GPS";
    case RinexTimeSystem::kGalileo: return "GAL";
    case RinexTimeSystem::kBeidou: return "BDT";
    case RinexTimeSystem::kQzss: return "QZS";
    case RinexTimeSystem::kIrnss: return "IRN";
    case RinexTimeSystem::kGlonass: return "GLO";
    case RinexTimeSystem::kUtc: return "UTC";
  }
  return "?";
}

RinexTimeSystem SystemTime(GnssSystem system) {
  switch (system) {
    case GnssSystem::kGalileo: return RinexTimeSystem::kGalileo;
    case GnssSystem::kBeidou: return RinexTimeSystem::kBeidou;
    case GnssSystem::kGlonass: return RinexTimeSystem::kGlonass;
    case GnssSystem::kQzss: return RinexTimeSystem::kQzss;
    case GnssSystem::kIrnss: return RinexTimeSystem::kIrnss;
    case GnssSystem::kGps: case GnssSystem::kSbas: break;
  }
  return RinexTimeSystem::kGps;
}

bool RinexToGpsSeconds(const RinexCalendar& c, RinexTimeSystem system, int leap_seconds, double* gps_s,
                       std::string* why) {
  int64_t days = 0;
  if (!CalendarDays(c.year, c.month, c.day, &days)) {
    *why = FormatText("date %04d-%02d-%02d is not a calendar day from 1980-01-06 on", c.year, c.month, c.day);
    return false;
  }
  // Second 60 is a UTC leap second; NaN fails every comparison and is refused with the rest.
  if (c.hour < 0 || c.hour > 23 || c.minute < 0 || c.minute > 59 || !(c.second >= 0.0 && c.second < 61.0)) {
    *why = FormatText("time %02d:%02d:%.7f is not a time of day", c.hour, c.minute, c.second);
    return false;
  }
  double offset = 0.0;  // GPS − the file's system
  if (system == RinexTimeSystem::kBeidou) {
    offset = kGpsMinusBdt;
  } else if (system == RinexTimeSystem::kGlonass || system == RinexTimeSystem::kUtc) {
    // RINEX dates GLONASS in UTC (not UTC(SU) + 3 h).
    if (leap_seconds < 0) {
      *why = std::string("time system ") + RinexTimeSystemName(system) +
             " needs GPS − UTC, and the header has no LEAP SECONDS";
      return false;
    }
    offset = leap_seconds;
  }
  // Whole seconds summed exactly, the fraction added once.
  const int64_t whole = days * 86400 + c.hour * 3600 + c.minute * 60 + static_cast<int64_t>(offset);
  *gps_s = static_cast<double>(whole) + c.second;
  return true;
}

GpsWeekTime ToGpsWeek(double gps_s) {
  GpsWeekTime w;
  w.week = static_cast<int>(std::floor(gps_s / kSecondsPerWeek));
  w.seconds_of_week = gps_s - w.week * kSecondsPerWeek;
  return w;
}

NumberStatus ParseRinexNumber(std::string_view field, double* value, bool* blank) {
  field = Trim(field);
  *blank = field.empty();
  *value = 0.0;
  if (field.empty()) return NumberStatus::kOk;
  char buf[40];
  if (field.size() >= sizeof(buf)) return NumberStatus::kBad;
  for (size_t i = 0; i < field.size(); ++i) {
    const char ch = field[i];
    buf[i] = ch == 'D' || ch == 'd' ? 'E' : ch;  // Fortran's double-precision exponent
  }
  return ParseNumber(std::string_view(buf, field.size()), value);
}

}  // namespace gins
