// Conversion of the i2Nav (Wuhan University) text formats, read by KF-GINS and OB_GINS, into a gins log
// (docs/formats.md §3), in one streaming pass over both files (bounded memory).
//
// The formats, as published by i2Nav (i2Nav-WHU/KF-GINS README §2.2 "Data format" and
// src/fileio/{imufileloader,gnssfileloader,fileloader}.h/.cc; i2Nav-WHU/awesome-gins-datasets README §2-3;
// OB_GINS reads the same files with the same loaders):
//   IMU   t dθx dθy dθz dvx dvy dvz: GPS seconds of week; angle increments (rad) and velocity increments
//         (m/s) over the interval (t_prev, t] ending at t (KF-GINS's gi_engine.h imuInterpolate splits an
//         increment linearly over exactly that interval); IMU axes forward-right-down (FRD). Columns past
//         the seventh are not IMU data (KF-GINS: "imudatalen ... only use the first seven columns").
//   GNSS  t lat lon h σn σe σv: GPS seconds of week, deg, deg, m (ellipsoidal), 1-σ north, east and
//         vertical in m. A 13-column variant carries GNSS velocity too; its σ are columns 8-10 (as
//         gnssfileloader.h reads them). Fields are split at spaces, tabs and commas (fileloader.cc).
// The gins log gets rates stamped at the middle of their interval (the mean rate over an interval is the
// rate at its midpoint to second order), body axes FLU (y and z negated), GNSS σ as east, north, up and
// heading_valid 0; records merged in time order (ties: IMU first). Times are kept as in the files.
//
// Checks (each names the file and line): column counts, numbers, NaN/inf, time order (out_of_order,
// duplicate; a GPS week rollover is named as such), ranges (the limits of the gins reader, so that the
// log reads back without damage), GNSS σ > 0; and, over the first IMU samples, whether the columns are
// what the format says (increments, not rates; m/s and rad, not g or degrees), and anywhere in the file
// that no turn faster than 5 rad/s lasts a second (degrees): a file that fails is refused whatever the
// damage policy. IMU and GNSS time ranges that do not overlap are refused (different
// time bases). An IMU interval over 1.5 times the nominal one is a gap: converted, and reported.
// Odometer: not converted. No i2Nav odometer file is publicly documented (OB_GINS's loader reads an 8th
// IMU column as a speed, undocumented; gins's ODOM needs pulses per wheel); extra IMU columns are ignored
// with a warning.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/io/log_reader.h"

namespace gins {

// What the IMU file's six data columns hold.
enum class I2navImuData {
  kIncrements,  // dθ (rad), dv (m/s) over (t_prev, t]: the i2Nav format
  kRates,       // ω (rad/s), f (m/s²) sampled at t, in the same FRD axes (a common variant)
};

struct I2navInputs {
  std::string imu_path;
  std::string gnss_path;
  I2navImuData imu_data = I2navImuData::kIncrements;
};

// What became of one input file.
struct ConvertedFile {
  std::string path;
  uint64_t lines = 0;    // lines read
  uint64_t written = 0;  // records written to the log
  int columns = 0;       // columns per line (fixed by the first good line)
  bool has_range = false;
  double t_first = 0.0, t_last = 0.0;          // time range of the accepted lines, as in the file
  std::map<std::string, uint64_t> skipped;     // damage reason -> lines skipped
  std::map<std::string, uint64_t> warnings;    // converted, but worth a look: key -> count
  std::vector<InputIssue> issues;              // the first few of each reason or warning, in file order
  static constexpr int kMaxExamplesPerReason = 5;
  uint64_t total_skipped() const;
};

struct I2navConversion {
  std::string out_path;
  std::string header;        // the comment line written first (without "# ")
  ConvertedFile imu, gnss;
  double imu_interval = 0.0;  // s, the nominal IMU sample period (median of the first intervals)
};

// Converts the i2Nav pair into a gins log at out_path (gzip if it ends in ".gz"), written completely or
// not at all. options: on_error (skip | stop), max_errors (per file) and max_line_length, with the gins
// reader's meaning; max_time_jump is not used. Throws InputError ("<file>:<line>: <reason>") on input
// that cannot be converted, std::runtime_error when the output cannot be written.
I2navConversion ConvertI2nav(const I2navInputs& inputs, const InputOptions& options, const std::string& out_path);

// The conversion in a few lines for a person: records per file, time ranges, skipped lines and warnings by
// reason with the first line of each.
std::string FormatConversionSummary(const I2navConversion& conversion);

}  // namespace gins
