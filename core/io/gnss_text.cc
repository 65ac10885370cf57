#include "core/io/gnss_text.h"

#include <cerrno>
#include <cstring>

namespace gins {
namespace {

using input_reason::kLineTooLong;
using input_reason::kTruncated;

constexpr int64_t kDay = 86400;
constexpr int64_t kWeek = 604800;
// Days from 1970-01-01 to the GPS epoch, 1980-01-06.
constexpr int64_t kGpsEpochDays = static_cast<int64_t>(kGpsEpochUnix) / kDay;

bool AllDigits(std::string_view s) {
  if (s.empty()) return false;
  for (const char c : s) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

// An unsigned integer of at most `max_digits` digits.
bool ParseUnsigned(std::string_view s, size_t max_digits, int64_t* value) {
  if (!AllDigits(s) || s.size() > max_digits) return false;
  int64_t v = 0;
  for (const char c : s) v = v * 10 + (c - '0');
  *value = v;
  return true;
}

// "a<sep>b<sep>c" with one of the given separators into three unsigned integers.
bool ParseTriple(std::string_view s, const char* separators, size_t max_digits, int64_t out[3]) {
  for (int k = 0; k < 3; ++k) {
    const size_t end = k < 2 ? s.find_first_of(separators) : s.size();
    if (end == std::string_view::npos || !ParseUnsigned(s.substr(0, end), max_digits, &out[k])) return false;
    s.remove_prefix(k < 2 ? end + 1 : end);
  }
  return true;
}

}  // namespace

InputLines::InputLines(ConvertedFile* file, const InputOptions& options)
    : file_(file), lines_(file->path, options.max_line_length), issues_(file, options) {}

bool InputLines::Next(TextLine* line) {
  while (lines_.Next(line)) {
    ++file_->lines;
    if (line->too_long) {
      issues_.Damage(line->number, kLineTooLong,
                     FormatText("line of %llu characters, the limit is %zu",
                                static_cast<unsigned long long>(line->length), lines_.max_line()));
      continue;
    }
    if (!line->terminated && lines_.read_errno() != 0) {
      throw InputError(file_->path + ":" + std::to_string(line->number) +
                       ": cannot read: " + std::strerror(lines_.read_errno()));
    }
    if (!line->terminated && lines_.stream_error()) {  // a cut gzip stream's last bytes are a fragment
      stream_error_reported_ = true;
      issues_.Damage(line->number, kTruncated,
                     "gzip stream cut short or corrupt (" + lines_.stream_message() + "), partial last line dropped");
      continue;
    }
    return true;
  }
  EndOfData();
  return false;
}

void InputLines::EndOfData() {
  if (lines_.read_errno() != 0) {
    throw InputError(file_->path + ":" + std::to_string(lines_.lines() + 1) +
                     ": cannot read: " + std::strerror(lines_.read_errno()));
  }
  if (lines_.stream_error() && !stream_error_reported_) {
    stream_error_reported_ = true;
    issues_.Damage(lines_.lines() + 1, kTruncated,
                   "gzip stream cut short or corrupt (" + lines_.stream_message() + ")");
  }
}

void InputLines::Damage(const TextLine& line, const char* reason, const std::string& detail) {
  if (line.terminated) {
    issues_.Damage(line.number, reason, detail);
  } else {
    issues_.Damage(line.number, kTruncated,
                   "last line has no newline and is damaged: " + std::string(reason) + ": " + detail);
  }
}

void SplitFields(std::string_view text, FieldSplit mode, char separator, std::vector<std::string_view>* fields) {
  fields->clear();
  if (mode == FieldSplit::kExact) {
    for (;;) {
      const size_t end = text.find(separator);
      fields->push_back(text.substr(0, end));
      if (end == std::string_view::npos) return;
      text.remove_prefix(end + 1);
    }
  }
  auto is_space = [](char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r' || c == '\v' || c == '\f'; };
  for (size_t i = 0; i < text.size();) {
    while (i < text.size() && is_space(text[i])) ++i;
    if (i == text.size()) break;
    const size_t start = i;
    while (i < text.size() && !is_space(text[i])) ++i;
    fields->push_back(text.substr(start, i - start));
  }
}

bool ParseSecondsToken(std::string_view token, int64_t* whole, double* frac) {
  const size_t dot = token.find('.');
  if (!ParseUnsigned(token.substr(0, dot), 9, whole)) return false;
  *frac = 0.0;
  if (dot == std::string_view::npos || dot + 1 == token.size()) return true;
  const std::string_view decimals = token.substr(dot);  // ".750": the same double as 0.750
  return AllDigits(decimals.substr(1)) && decimals.size() <= 24 && ParseNumber(decimals, frac) == NumberStatus::kOk;
}

bool CalendarDays(int year, int month, int day, int64_t* days) {
  if (year < 1980 || year > 2200 || month < 1 || month > 12 || day < 1 || day > 31) return false;
  UtcCalendar c;
  c.year = year;
  c.month = month;
  c.day = day;
  const double unix_midnight = FromUtcCalendar(c);
  const UtcCalendar back = ToUtcCalendar(unix_midnight);  // 31 April comes back as 1 May
  if (back.year != year || back.month != month || back.day != day) return false;
  *days = static_cast<int64_t>(unix_midnight) / kDay - kGpsEpochDays;
  return *days >= 0;
}

bool ParseCalendarTime(std::string_view date, std::string_view time, SplitTime* t, std::string* why) {
  int64_t ymd[3];
  int64_t days = 0;
  if (!ParseTriple(date, "/-", 4, ymd) ||
      !CalendarDays(static_cast<int>(ymd[0]), static_cast<int>(ymd[1]), static_cast<int>(ymd[2]), &days)) {
    *why = "date " + QuoteToken(date) + " is not a calendar date YYYY/MM/DD from 1980-01-06 on";
    return false;
  }
  // HH:MM and SS.sss apart: the seconds carry the fraction.
  const size_t colon = time.rfind(':');
  int64_t sec = 0, hm[2];
  double frac = 0.0;
  const std::string_view hhmm = colon == std::string_view::npos ? std::string_view() : time.substr(0, colon);
  const size_t colon2 = hhmm.find(':');
  if (colon == std::string_view::npos || colon2 == std::string_view::npos ||
      !ParseUnsigned(hhmm.substr(0, colon2), 2, &hm[0]) || !ParseUnsigned(hhmm.substr(colon2 + 1), 2, &hm[1]) ||
      !ParseSecondsToken(time.substr(colon + 1), &sec, &frac) || hm[0] > 23 || hm[1] > 59 || sec > 60 ||
      (sec == 60 && (hm[0] != 23 || hm[1] != 59))) {
    *why = "time " + QuoteToken(time) + " is not HH:MM:SS.SSS";
    return false;
  }
  t->whole = days * kDay + hm[0] * 3600 + hm[1] * 60 + sec;
  t->frac = frac;
  t->leap_second = sec == 60;
  return true;
}

bool ParseWeekSeconds(std::string_view week, std::string_view seconds, SplitTime* t, std::string* why) {
  int64_t w = 0, s = 0;
  double frac = 0.0;
  if (!ParseUnsigned(week, 5, &w) || !ParseSecondsToken(seconds, &s, &frac) || s >= kWeek) {
    *why = "week " + QuoteToken(week) + " and seconds of week " + QuoteToken(seconds) +
           " are not WWWW SSSSSS.SSS (seconds in [0, 604800))";
    return false;
  }
  t->whole = w * kWeek + s;
  t->frac = frac;
  t->leap_second = false;
  return true;
}

bool ParseNmeaTimeOfDay(std::string_view token, int64_t* sod_whole, double* frac, bool* leap_second) {
  int64_t hhmmss = 0;
  const size_t dot = token.find('.');
  if (token.substr(0, dot).size() != 6 || !ParseSecondsToken(token, &hhmmss, frac)) return false;
  const int64_t h = hhmmss / 10000, m = hhmmss / 100 % 100, s = hhmmss % 100;
  if (h > 23 || m > 59 || s > 60 || (s == 60 && (h != 23 || m != 59))) return false;
  *sod_whole = h * 3600 + m * 60 + s;
  *leap_second = s == 60;
  return true;
}

bool ParseNmeaDate(std::string_view ddmmyy, int64_t* days) {
  int64_t v = 0;
  if (ddmmyy.size() != 6 || !ParseUnsigned(ddmmyy, 6, &v)) return false;
  const int yy = static_cast<int>(v % 100);
  return CalendarDays(yy >= 80 ? 1900 + yy : 2000 + yy, static_cast<int>(v / 100 % 100), static_cast<int>(v / 10000),
                      days);
}

double ToLogTime(const SplitTime& t, TimeSystem system, LogTimeScale scale, int* leap_seconds) {
  const int64_t epoch = static_cast<int64_t>(kGpsEpochUnix);
  int64_t whole = t.whole;  // on the log's scale, from its epoch
  int leap = 0;
  if (system == TimeSystem::kUtc && scale == LogTimeScale::kGps) {
    // 23:59:60 is counted with the leap seconds before it: one second after 23:59:59, one before midnight.
    leap = GpsMinusUtc(static_cast<double>(t.whole + epoch - (t.leap_second ? 1 : 0)));
    whole = t.whole + leap;
  } else if (system == TimeSystem::kUtc) {
    whole = t.whole + epoch;
  } else if (scale == LogTimeScale::kUnixUtc) {
    const int64_t unix_whole = static_cast<int64_t>(GpsToUnixUtc(static_cast<double>(t.whole)));
    leap = static_cast<int>(t.whole + epoch - unix_whole);
    whole = unix_whole;
  }
  if (leap_seconds != nullptr) *leap_seconds = leap;
  return static_cast<double>(whole) + t.frac;
}

}  // namespace gins
