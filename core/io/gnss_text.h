// What the readers of receiver and GNSS-software formats (core/io/gnss_formats.h) share: the lines of an
// input under the gins damage policy, field splitting, and the time forms those files write, each parsed
// once into an exact split time and turned into the log's clock in one place (docs/formats.md §6).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/io/i2nav_columns.h"  // ConvertedFile, FileIssues, FormatText: one damage policy for every converter
#include "core/io/text_input.h"
#include "core/time_scales.h"

namespace gins {

// Damage reasons of the GNSS formats, beyond the log reader's (input_reason).
namespace gnss_reason {
inline constexpr char kBadChecksum[] = "bad_checksum";        // NMEA: the '*HH' does not match the sentence
inline constexpr char kBadTime[] = "bad_time";                // a time or date field that is not one
inline constexpr char kMissingDate[] = "missing_date";        // NMEA: an epoch before any RMC or ZDA date
inline constexpr char kTimeBackwards[] = "time_backwards";    // not later than the previous epoch
inline constexpr char kUnknownQuality[] = "unknown_quality";  // a quality flag the format does not define
inline constexpr char kNotNmea[] = "not_nmea";                // NMEA: a line with no '$' sentence
}  // namespace gnss_reason

// The lines of one input file: too long lines, a cut gzip stream and read errors are handled here (damage
// or InputError), every other line is handed on to be parsed. Counts lines into the ConvertedFile.
class InputLines {
 public:
  InputLines(ConvertedFile* file, const InputOptions& options);
  bool Next(TextLine* line);  // false at the end of the data
  // A line that does not parse: damaged with its reason, or `truncated` if it is the last line and lacks
  // its newline (most likely cut mid-write, as the log reader judges it).
  void Damage(const TextLine& line, const char* reason, const std::string& detail);
  FileIssues& issues() { return issues_; }
  const std::string& path() const { return file_->path; }

 private:
  void EndOfData();
  ConvertedFile* file_;
  LineSource lines_;
  FileIssues issues_;
  bool stream_error_reported_ = false;
};

// Fields of a line. kWhitespace: split at runs of spaces, tabs and commas (RTKLIB's columns, any
// out-fieldsep); kExact: at each `separator`, empty fields kept (NMEA, CSV). Views into `text`.
enum class FieldSplit { kWhitespace, kExact };
void SplitFields(std::string_view text, FieldSplit mode, char separator, std::vector<std::string_view>* fields);

// A time as whole seconds since 1980-01-06 00:00:00 on its own time system plus the fraction of a second,
// both taken from the text: exact for any number of decimals, and rounded once when it becomes a log time.
struct SplitTime {
  int64_t whole = 0;
  double frac = 0.0;         // [0, 1)
  bool leap_second = false;  // UTC 23:59:60: `whole` is then the next midnight's count
};

enum class TimeSystem { kGpst, kUtc };

// "12", "12.345": the integer part and the fraction of an unsigned decimal token; false for anything else
// (signs, exponents, more than 9 integer digits).
bool ParseSecondsToken(std::string_view token, int64_t* whole, double* frac);
// RTKLIB's calendar form "YYYY/MM/DD" "HH:MM:SS.SSS" (also with '-' in the date); seconds up to 60.999
// (a leap second). false with *why.
bool ParseCalendarTime(std::string_view date, std::string_view time, SplitTime* t, std::string* why);
// GPS week and seconds of week "WWWW" "SSSSSS.SSS" (RTKLIB writes UTC times in this form too).
bool ParseWeekSeconds(std::string_view week, std::string_view seconds, SplitTime* t, std::string* why);
// NMEA's time of day "hhmmss[.ss]": seconds of the day split; second 60 is a leap second.
bool ParseNmeaTimeOfDay(std::string_view token, int64_t* sod_whole, double* frac, bool* leap_second);
// Days since 1980-01-06 of an NMEA RMC date "ddmmyy" (years 80-99 are 19xx, else 20xx) or of day, month and
// a four-digit year (ZDA, --date); false unless a real calendar date from 1980-01-06 on.
bool ParseNmeaDate(std::string_view ddmmyy, int64_t* days);
bool CalendarDays(int year, int month, int day, int64_t* days);

// The time on the log's clock (docs/formats.md §2.6: GPS seconds since 1980-01-06, or Unix UTC), and the
// whole seconds of GPS − UTC that the conversion applied (0 when the file and the log share a scale).
double ToLogTime(const SplitTime& t, TimeSystem system, LogTimeScale scale, int* leap_seconds);

}  // namespace gins
