// RINEX 3.0x observation and navigation files (the first input of tightly coupled GNSS): satellite ids,
// RINEX times as GPS seconds (rinex_fields.cc), a streamed observation reader (rinex_obs.cc) and a
// navigation reader (rinex_nav.cc). Plain or gzip files (LineSource).
//
// Format summary (RINEX 3.04, IGS/RTCM; fixed columns, 1-based below; header labels in columns 61-80):
//   Header, both files: "RINEX VERSION / TYPE" (version F9.2 in 1-9, type in 21: 'O' or 'N', system in
//   41: G R E C J S I or M mixed) ... "END OF HEADER". Only versions 3.00 <= v < 4 are read.
//   Observation header: "SYS / # / OBS TYPES" (system in 1, count I3 in 4-6, then 13 codes of 4 columns
//   from 7, continuation lines blank in 1-6), "APPROX POSITION XYZ" (3F14.4, m, ECEF), "ANTENNA: DELTA
//   H/E/N" (3F14.4, m), "TIME OF FIRST OBS" (5I6,F13.7, time system A3 in 49-51: GPS GAL BDT GLO QZS IRN
//   UTC), "INTERVAL" (F10.3, s), "LEAP SECONDS" (I6).
//   Observation epoch: '>' in 1, year 3-6, month 8-9, day 11-12, hour 14-15, minute 17-18, second 19-29
//   (F11.7), epoch flag 32 (0 ok, 1 power failure before it, 2-5 events, 6 cycle slips), satellites or
//   special records I3 in 33-35, receiver clock offset F15.12 (s) in 42-56, optional. Flags 0, 1 and 6 are
//   followed by one line per satellite: id A3 (system letter, PRN I2) then per observation type of its
//   system 16 columns: value F14.3, LLI I1 (loss of lock: bit 0 lost lock, bit 1 half-cycle ambiguity),
//   signal strength I1 (1..9); blank = missing (lines may stop early). Flags 2-5: that many header lines.
//   Units by the code's first letter: C pseudorange m, L carrier phase cycles, D Doppler Hz, S C/N0 dB-Hz.
//   Navigation header: "IONOSPHERIC CORR" (type A4: GPSA GPSB GAL BDSA BDSB QZSA ..., then up to four
//   D12.4 from column 6), "TIME SYSTEM CORR" (type A4, a0 D17.10, a1 D16.9, T ref I7, week I5),
//   "LEAP SECONDS" (I6 in 1-6: GPS − UTC, s).
//   Navigation record: id A3 and epoch (year I5 and 5 × I3 in 4-23) then three D19.12 in 24-80; then
//   continuation lines of four D19.12 from column 5 ('D' exponents; fields may be blank). G E C J I:
//   8 lines (Keplerian orbit); R S: 4 lines (state vector); R 5 lines from version 3.05 on.
//   The epoch of a record is on its system's time: GPS, GAL (= GPS), BDT (= GPS − 14 s), SBAS GPS,
//   GLONASS UTC.
//
// Damage follows the gins policy (InputOptions: on_error skip | stop, max_errors), counted into a
// ConvertedFile by reason (input_reason, gnss_reason keys): a damaged satellite line is skipped (its epoch
// keeps the other satellites); a damaged epoch line, or an epoch that does not have the satellite lines
// it announces (cut at the end of the file: truncated; cut by the next '>': missing_fields), is skipped
// whole; a damaged navigation record is skipped whole. A satellite line longer than input.max_line_length
// costs its epoch too (line_too_long, then missing_fields). A header that cannot be read is refused
// (InputError whatever the policy), naming its line; so is a GLONASS or UTC time without LEAP SECONDS.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/gnss_ephemeris.h"
#include "core/io/gnss_text.h"
#include "core/io/log_reader.h"

namespace gins {

// The system of a RINEX letter (G R E C J S I); false for any other.
bool ParseGnssSystem(char letter, GnssSystem* system);
// "G05", "E19", "G 5" (RINEX 2 style blank): a system letter and a PRN 1..99; false for anything else.
bool ParseSatelliteId(std::string_view text, SatelliteId* id);

// The time systems a RINEX file dates its epochs in.
enum class RinexTimeSystem { kGps, kGalileo, kBeidou, kQzss, kIrnss, kGlonass, kUtc };
// "GPS" "GAL" "BDT" "QZS" "IRN" "GLO" "UTC"; false for any other.
bool ParseRinexTimeSystem(std::string_view text, RinexTimeSystem* system);
const char* RinexTimeSystemName(RinexTimeSystem system);
// A system's own time scale (G→GPS, E→GAL, C→BDT, R→GLO, J→QZS, I→IRN, S→GPS).
RinexTimeSystem SystemTime(GnssSystem system);


// GPS seconds since 1980-01-06 00:00:00 of a calendar epoch on `system`. GLONASS and UTC epochs need GPS −
// UTC (`leap_seconds`, s; < 0: unknown). False with *why for an invalid date (before 1980-01-06 or not a
// calendar day, hour > 23, ...) or a missing leap second count.
bool RinexToGpsSeconds(const RinexCalendar& c, RinexTimeSystem system, int leap_seconds, double* gps_s,
                       std::string* why);

// GPS week and seconds of week of GPS seconds since 1980-01-06.
struct GpsWeekTime {
  int week = 0;
  double seconds_of_week = 0.0;
};
GpsWeekTime ToGpsWeek(double gps_s);

// ---------------------------------------------------------------------------------------------------------
// Observation files

struct RinexObsHeader {
  double version = 0.0;
  char file_system = 'M';  // 'M' mixed or a system letter
  // Observation codes per system in file order ("C1C", "L1C", "D1C", "S1C", ...).
  std::map<GnssSystem, std::vector<std::string>> obs_types;
  bool has_approx_position = false;
  std::array<double, 3> approx_position_ecef_m = {0.0, 0.0, 0.0};
  std::array<double, 3> antenna_delta_hen_m = {0.0, 0.0, 0.0};  // height, east, north of the ARP
  RinexTimeSystem time_system = RinexTimeSystem::kGps;  // of every epoch (TIME OF FIRST OBS)
  double first_obs_gps_s = 0.0;
  double interval_s = 0.0;  // 0: no INTERVAL line
  int leap_seconds = -1;    // GPS − UTC, s; -1: no LEAP SECONDS line
  uint64_t lines = 0;       // lines of the header, END OF HEADER included
};

// One observation of one signal. lli and ssi are 0 when blank (RINEX: blank = 0 = not known).
struct RinexObservation {
  std::string code;    // "C1C": type C (m), L (cycles), D (Hz), S (dB-Hz); band; attribute
  double value = 0.0;  // in the type's unit
  int lli = 0;         // loss of lock indicator 0..7
  int ssi = 0;         // signal strength 0..9
};

// The observations of one satellite in one epoch: only those present (blank values are left out).
struct RinexSatelliteObs {
  SatelliteId sat;
  std::vector<RinexObservation> obs;
  const RinexObservation* Find(std::string_view code) const;  // nullptr if absent
};

struct RinexObsEpoch {
  double gps_s = 0.0;  // receiver time of the epoch, GPS seconds since 1980-01-06
  int flag = 0;        // 0 ok, 1 power failure between the previous epoch and this one
  bool has_clock_offset = false;
  double receiver_clock_offset_s = 0.0;
  std::vector<RinexSatelliteObs> satellites;  // in file order
  uint64_t line = 0;                          // of its '>' line
};

struct RinexObsStats {
  uint64_t epochs = 0;              // given by Next
  uint64_t satellite_records = 0;   // satellites given, summed over epochs
  uint64_t event_epochs = 0;        // flags 2-5 read (their header lines skipped; flag 4's applied)
  uint64_t event_lines = 0;         // special records of those events
  uint64_t cycle_slip_epochs = 0;   // flag 6 records read and skipped (their lines repeat the epoch's)
  uint64_t cycle_slip_lines = 0;
};

// Streams the epochs of an observation file, one at a time; memory holds one epoch. The constructor reads
// the header (InputError if the file cannot be opened or the header not read).
class RinexObsReader {
 public:
  RinexObsReader(const std::string& path, const InputOptions& options);
  ~RinexObsReader();
  RinexObsReader(const RinexObsReader&) = delete;
  RinexObsReader& operator=(const RinexObsReader&) = delete;

  // The next epoch of observations (flag 0 or 1) in strictly increasing time; false at the end of the file.
  // Throws InputError under the stop policy or past max_errors.
  bool Next(RinexObsEpoch* epoch);

  const RinexObsHeader& header() const { return header_; }
  const RinexObsStats& stats() const { return stats_; }
  const ConvertedFile& file() const { return file_; }  // lines read, damage by reason with examples

 private:
  class Impl;
  RinexObsHeader header_;
  RinexObsStats stats_;
  ConvertedFile file_;
  std::unique_ptr<Impl> impl_;
};

// ---------------------------------------------------------------------------------------------------------
// Navigation files

// "IONOSPHERIC CORR": GPSA α0..α3 (s, s/sc, s/sc², s/sc³), GPSB β0..β3 (s .. s/sc³): Klobuchar; GAL ai0
// (sfu), ai1 (sfu/deg), ai2 (sfu/deg²): NeQuick; BDSA/BDSB: BeiDou's Klobuchar; QZSA/QZSB, IRNA/IRNB.
struct RinexIonoCorrection {
  std::string type;  // "GPSA", "GAL", ...
  std::array<double, 4> params = {0.0, 0.0, 0.0, 0.0};
};

// "TIME SYSTEM CORR": system_a − system_b = a0 + a1 (t − T_ref), e.g. GAUT (GAL − UTC), GPUT, GPGA.
struct RinexTimeCorrection {
  std::string type;  // "GAUT", "GPUT", "BDUT", "GAGP", ...
  double a0_s = 0.0;
  double a1_s_s = 0.0;
  int ref_seconds_of_week = 0;
  int ref_week = 0;
};

struct RinexNavHeader {
  double version = 0.0;
  char file_system = 'M';
  std::vector<RinexIonoCorrection> iono;
  std::vector<RinexTimeCorrection> time_corrections;
  int leap_seconds = -1;  // GPS − UTC, s; -1: no LEAP SECONDS line
  uint64_t lines = 0;
};


// A state-vector broadcast ephemeris (GLONASS, SBAS): position, velocity and acceleration, PZ-90 or WGS 84.
struct StateVectorEphemeris {
  SatelliteId sat;
  uint64_t line = 0;
  RinexCalendar toc;
  double toc_gps_s = 0.0;
  double clock_bias_s = 0.0;     // GLONASS −TauN, SBAS aGf0
  double clock_drift_s_s = 0.0;  // GLONASS +GammaN (relative frequency bias), SBAS aGf1
  double message_frame_time_s = 0.0;  // GLONASS: seconds of the UTC week; SBAS: transmission time (GPS s of week)
  std::array<double, 3> position_km = {0.0, 0.0, 0.0};
  std::array<double, 3> velocity_km_s = {0.0, 0.0, 0.0};
  std::array<double, 3> acceleration_km_s2 = {0.0, 0.0, 0.0};
  double health = 0.0;
  double frequency_number_or_ura = 0.0;  // GLONASS frequency number −7..+13; SBAS accuracy code (URA)
  double age_or_iodn = 0.0;              // GLONASS age of operation information (days); SBAS IODN
};

struct RinexNav {
  RinexNavHeader header;
  std::vector<KeplerEphemeris> kepler;        // G E C J I, in file order
  std::vector<StateVectorEphemeris> state;    // R S, in file order
  std::map<GnssSystem, uint64_t> records;     // records read, by system
  ConvertedFile file;                         // lines, damage by reason with examples
};

// Reads a whole navigation file (they are small). Throws InputError if the file cannot be opened, its
// header not read, under the stop policy, or past max_errors.
RinexNav ReadRinexNav(const std::string& path, const InputOptions& options);

// A RINEX number (F or D format, 'D' exponent) in a fixed-width field, leading and trailing blanks trimmed.
// kOk with *value; *blank when the field is all blanks (then *value = 0, kOk).
NumberStatus ParseRinexNumber(std::string_view field, double* value, bool* blank);

// Column helpers of both readers.
namespace rinex_internal {
// Columns [first, first + width) of a line, 1-based as the format counts them; shorter (or empty) where the
// line ends early.
std::string_view Column(std::string_view line, size_t first, size_t width);
std::string_view Trim(std::string_view s);
bool IsBlank(std::string_view s);
// An optionally signed decimal integer, blanks around it allowed; false for a blank or anything else.
bool ParseInt(std::string_view field, int* value);
// One line read ahead and put back for the next read (a record ends where the next one begins).
class HeldLine {
 public:
  bool Take(TextLine* line) {
    if (!held_) return false;
    held_ = false;
    *line = line_;
    line->text = text_;
    return true;
  }
  void Put(const TextLine& line) {
    text_.assign(line.text);
    line_ = line;
    held_ = true;
  }
  bool holds() const { return held_; }

 private:
  bool held_ = false;
  std::string text_;  // the line's own copy: the source's buffer moves on
  TextLine line_;
};
// The header label (columns 61-80, trimmed).
inline std::string_view Label(std::string_view line) { return Trim(Column(line, 61, 20)); }
// The calendar epoch of a navigation record or TIME OF FIRST OBS-like fields: year, month, day, hour,
// minute as integers, the second as a number. False unless each parses.
bool ParseCalendarFields(std::string_view year, std::string_view month, std::string_view day, std::string_view hour,
                         std::string_view minute, std::string_view second, RinexCalendar* c);
}  // namespace rinex_internal

}  // namespace gins
