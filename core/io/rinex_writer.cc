// RINEX 3.04 observation writer (core/io/rinex_writer.h).
#include "core/io/rinex_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <stdexcept>

#include "core/time_scales.h"

namespace gins {

namespace {

constexpr int64_t kTicksPerSecond = 10000000;  // the epoch line's 1e-7 s
constexpr int64_t kGpsEpochUnixDays = 3657;    // 1980-01-06 in days since 1970-01-01

// Whole seconds and 1e-7 s ticks of GPS seconds, rounded once (the fraction of a double near 1.4e9 is exact).
void SplitTicks(double gps_s, int64_t* whole, int64_t* ticks) {
  const double floor_s = std::floor(gps_s);
  *whole = static_cast<int64_t>(floor_s);
  *ticks = std::llround((gps_s - floor_s) * static_cast<double>(kTicksPerSecond));
  if (*ticks >= kTicksPerSecond) {
    ++*whole;
    *ticks -= kTicksPerSecond;
  }
}

struct CalendarTicks {
  int year, month, day, hour, minute, second;
  int64_t ticks;
};
CalendarTicks CalendarOf(double gps_s) {
  int64_t whole = 0, ticks = 0;
  SplitTicks(gps_s, &whole, &ticks);
  CalendarTicks c;
  const int64_t days = whole / 86400, rest = whole % 86400;
  CivilFromDays(days + kGpsEpochUnixDays, &c.year, &c.month, &c.day);
  c.hour = static_cast<int>(rest / 3600);
  c.minute = static_cast<int>(rest % 3600 / 60);
  c.second = static_cast<int>(rest % 60);
  c.ticks = ticks;
  return c;
}

std::string Printf(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string Printf(const char* format, ...) {
  char buf[256];
  va_list args;
  va_start(args, format);
  const int n = std::vsnprintf(buf, sizeof(buf), format, args);
  va_end(args);
  return std::string(buf, static_cast<size_t>(std::max(0, std::min(n, static_cast<int>(sizeof(buf)) - 1))));
}

// A header line: its content in columns 1-60, the label in 61-80.
std::string Line(std::string content, const char* label) {
  content.resize(60, ' ');
  std::string l = content + label;
  l.resize(80, ' ');
  while (!l.empty() && l.back() == ' ') l.pop_back();
  return l + "\n";
}

std::string Fit(const std::string& s, size_t width) {
  std::string out = s.substr(0, width);
  out.resize(width, ' ');
  return out;
}

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("RINEX writer: " + message);
}

}  // namespace

RinexCalendar GpsSecondsToCalendar(double gps_s) {
  const CalendarTicks t = CalendarOf(gps_s);
  RinexCalendar c;
  c.year = t.year;
  c.month = t.month;
  c.day = t.day;
  c.hour = t.hour;
  c.minute = t.minute;
  c.second = t.second + static_cast<double>(t.ticks) / kTicksPerSecond;
  return c;
}

std::string FormatRinexObsHeader(const RinexObsHeader& h, const RinexObsFileInfo& info) {
  Require(h.time_system == RinexTimeSystem::kGps, "only GPS time is written");
  Require(!h.obs_types.empty(), "the header lists no observation types");
  const CalendarTicks first = CalendarOf(h.first_obs_gps_s);
  std::string out;
  out += Line(Printf("%9.2f%11s%-20s%c", 3.04, "", "OBSERVATION DATA", h.file_system), "RINEX VERSION / TYPE");
  const std::string date = info.date.empty() ? Printf("%04d%02d%02d %02d%02d%02d UTC", first.year, first.month,
                                                      first.day, first.hour, first.minute, first.second)
                                             : info.date;
  out += Line(Fit(info.program, 20) + Fit(info.run_by, 20) + Fit(date, 20), "PGM / RUN BY / DATE");
  out += Line(Fit(info.marker_name, 60), "MARKER NAME");
  out += Line(Fit("gins", 20) + Fit("gins", 40), "OBSERVER / AGENCY");
  out += Line(Fit("0", 20) + Fit(info.receiver_type, 20) + Fit("0", 20), "REC # / TYPE / VERS");
  out += Line(Fit("0", 20) + Fit(info.antenna_type, 20), "ANT # / TYPE");
  if (h.has_approx_position) {
    const auto& p = h.approx_position_ecef_m;
    out += Line(Printf("%14.4f%14.4f%14.4f", p[0], p[1], p[2]), "APPROX POSITION XYZ");
  }
  const auto& d = h.antenna_delta_hen_m;
  out += Line(Printf("%14.4f%14.4f%14.4f", d[0], d[1], d[2]), "ANTENNA: DELTA H/E/N");
  for (const auto& [system, codes] : h.obs_types) {
    Require(!codes.empty() && codes.size() <= 999, std::string("system ") + static_cast<char>(system) +
                                                       " has no observation types (or more than 999)");
    // A1,2X,I3 then 13 codes of 1X,A3 per line; continuation lines blank in 1-6.
    std::string content = Printf("%c  %3zu", static_cast<char>(system), codes.size());
    for (size_t k = 0; k < codes.size(); ++k) {
      Require(codes[k].size() == 3, "observation code '" + codes[k] + "' is not 3 characters");
      if (k > 0 && k % 13 == 0) {
        out += Line(content, "SYS / # / OBS TYPES");
        content = std::string(6, ' ');
      }
      content += " " + codes[k];
    }
    out += Line(content, "SYS / # / OBS TYPES");
  }
  out += Line(Printf("%6d%6d%6d%6d%6d%5d.%07lld%5s%s", first.year, first.month, first.day, first.hour,
                     first.minute, first.second, static_cast<long long>(first.ticks), "", "GPS"),
              "TIME OF FIRST OBS");
  if (h.interval_s > 0.0) out += Line(Printf("%10.3f", h.interval_s), "INTERVAL");
  if (h.leap_seconds >= 0) out += Line(Printf("%6d", h.leap_seconds), "LEAP SECONDS");
  out += Line("", "END OF HEADER");
  return out;
}

std::string FormatRinexObsEpoch(const RinexObsHeader& h, const RinexObsEpoch& e) {
  Require(e.flag >= 0 && e.flag <= 6, Printf("epoch flag %d is not 0..6", e.flag));
  Require(e.satellites.size() <= 999, Printf("%zu satellites in one epoch (at most 999)", e.satellites.size()));
  const CalendarTicks t = CalendarOf(e.gps_s);
  std::string out = Printf("> %4d %02d %02d %02d %02d%3d.%07lld  %1d%3zu", t.year, t.month, t.day, t.hour,
                           t.minute, t.second, static_cast<long long>(t.ticks), e.flag, e.satellites.size());
  if (e.has_clock_offset) {
    Require(std::fabs(e.receiver_clock_offset_s) < 10.0, "receiver clock offset not within ±10 s");
    out += Printf("%6s%15.12f", "", e.receiver_clock_offset_s);
  }
  out += "\n";
  for (const RinexSatelliteObs& s : e.satellites) {
    const auto it = h.obs_types.find(s.sat.system);
    Require(it != h.obs_types.end(), s.sat.ToString() + ": the header lists no types for its system");
    const std::vector<std::string>& codes = it->second;
    std::string line = Printf("%c%02d", static_cast<char>(s.sat.system), s.sat.prn);
    std::vector<const RinexObservation*> by_code(codes.size(), nullptr);
    for (const RinexObservation& o : s.obs) {
      size_t k = 0;
      while (k < codes.size() && codes[k] != o.code) ++k;
      Require(k < codes.size(), s.sat.ToString() + ": code '" + o.code + "' is not in the header's list");
      by_code[k] = &o;
    }
    for (const RinexObservation* o : by_code) {
      if (!o) {
        line += std::string(16, ' ');
        continue;
      }
      Require(std::isfinite(o->value) && o->value > -1e9 && o->value < 1e10,
              s.sat.ToString() + " " + o->code + Printf(": %g does not fit F14.3", o->value));
      Require(o->lli >= 0 && o->lli <= 7 && o->ssi >= 0 && o->ssi <= 9,
              s.sat.ToString() + " " + o->code + ": LLI or SSI out of range");
      // 0 is written blank: RINEX's blank is "not known", which the reader gives back as 0.
      line += Printf("%14.3f", o->value);
      line += o->lli ? static_cast<char>('0' + o->lli) : ' ';
      line += o->ssi ? static_cast<char>('0' + o->ssi) : ' ';
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line + "\n";
  }
  return out;
}

RinexObsWriter::RinexObsWriter(const std::string& path, const RinexObsHeader& header, const RinexObsFileInfo& info)
    : header_(header), file_(path) {
  file_.Write(FormatRinexObsHeader(header_, info));
}

void RinexObsWriter::Add(const RinexObsEpoch& epoch) {
  file_.Write(FormatRinexObsEpoch(header_, epoch));
  ++epochs_;
}

void RinexObsWriter::Commit() { file_.Commit(); }

}  // namespace gins
