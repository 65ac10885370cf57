// RINEX 3.04 observation files written (the reader is core/io/rinex.h; its format summary holds for the
// columns here): a header from a RinexObsHeader, then epochs in GPS time, through an AtomicFile so that a
// failed run leaves no half-written file. What is written reads back through RinexObsReader to the
// format's resolution: values 0.001 (F14.3), epochs 1e-7 s (F11.7), the clock offset 1e-12 s (F15.12).
#pragma once

#include <string>

#include "core/io/rinex.h"
#include "core/io/trajectory_writer.h"

namespace gins {

// The calendar epoch (GPS time) of GPS seconds since 1980-01-06, the second rounded to 1e-7 s (the epoch
// line's resolution) with a carry into the minute, hour and day: 59.99999999 s is written as the next minute.
RinexCalendar GpsSecondsToCalendar(double gps_s);

// What the header says besides RinexObsHeader's fields.
struct RinexObsFileInfo {
  std::string marker_name = "GINS";
  std::string program = "gins";
  std::string run_by = "gins";
  // "YYYYMMDD HHMMSS UTC" of PGM / RUN BY / DATE. Empty: the first observation's epoch, so that a seeded
  // simulation writes the same bytes on every run.
  std::string date;
  std::string receiver_type = "GINS SIMULATED", antenna_type = "GINS SIMULATED";
};

// The header's lines (each ending in '\n'). Only GPS time is written (header.time_system kGps); the version
// line says 3.04 whatever header.version holds. Throws std::invalid_argument for another time system, an
// observation code that is not 3 characters, or a system without codes.
std::string FormatRinexObsHeader(const RinexObsHeader& header, const RinexObsFileInfo& info = {});

// One epoch's lines: the '>' line (flag, satellite count, the clock offset when has_clock_offset), then one
// line per satellite with every code of its system's list in header order (blanks where the satellite has
// none), trailing blanks cut. Throws std::invalid_argument for a satellite whose system the header does not
// list, a code not in its system's list, a value that F14.3 cannot hold (−1e9 < v < 1e10), LLI not 0..7,
// SSI not 0..9, a clock offset not within ±10 s, a flag not 0..6 or more than 999 satellites.
std::string FormatRinexObsEpoch(const RinexObsHeader& header, const RinexObsEpoch& epoch);

// The whole file: the header at construction, epochs by Add, renamed into place by Commit (destroyed
// uncommitted, the file is not there).
class RinexObsWriter {
 public:
  // Throws std::runtime_error if the file cannot be created, std::invalid_argument as FormatRinexObsHeader.
  RinexObsWriter(const std::string& path, const RinexObsHeader& header, const RinexObsFileInfo& info = {});
  void Add(const RinexObsEpoch& epoch);  // throws as FormatRinexObsEpoch
  void Commit();
  size_t epochs() const { return epochs_; }

 private:
  RinexObsHeader header_;
  AtomicFile file_;
  size_t epochs_ = 0;
};

}  // namespace gins
