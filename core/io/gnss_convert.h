// `gins convert --format rtklib-pos | nmea | csv`: the GNSS of a receiver's or GNSS software's file merged
// with the IMU and wheel records of a gins log (or of CSV files) into one gins log (docs/formats.md §6),
// in one streaming pass (bounded memory), written completely or not at all.
//
// The IMU side: `imu_path` is a gins log (its IMU and ODOM records are kept; its own GNSS and GVEL records
// are dropped and counted, the converted file takes their place), or a CSV file when imu_columns is given;
// wheel_path adds a CSV of wheel pulses. Records are merged in time order, stable: at equal times the IMU
// side first, then the wheels, then the GNSS record and its GVEL. Times: the GNSS file's (GPST or UTC, the
// leap seconds applied) on the log's clock (format.time_scale); the other files' as they are.
#pragma once

#include <cstdint>
#include <string>

#include "core/io/csv_columns.h"
#include "core/io/gnss_formats.h"

namespace gins {

struct GnssConvertInputs {
  std::string format;  // "rtklib-pos" | "nmea" | "csv"
  std::string gnss_path;
  std::string gnss_columns;  // csv: the GNSS file's column map (csv_columns.h)
  std::string imu_path;      // a gins log, or a CSV with imu_columns
  std::string imu_columns;
  std::string wheel_path;  // optional: a CSV of wheel pulses, with wheel_columns
  std::string wheel_columns;
  GnssFormatOptions options;
};

// One input of the conversion and what became of it.
struct ConvertedInput {
  std::string role;  // "GNSS", "IMU", "wheel"
  std::string kind;  // "rtklib-pos", "nmea", "csv", "gins log"
  ConvertedFile file;
  GnssFileStats stats;
  uint64_t dropped_gnss = 0, dropped_gvel = 0;  // a gins log's own GNSS and GVEL records, not written
};

struct GnssConversion {
  std::string out_path;
  std::string header;  // the comment line written first (without "# ")
  ConvertedInput gnss, imu, wheel;
  bool has_wheel = false;
  LogTimeScale time_scale = LogTimeScale::kGps;  // the log's clock
  RecordCounts written{};
  double t_first = 0.0, t_last = 0.0;            // the log's time span
};

// Converts into a gins log at out_path (gzip if it ends in ".gz"). options: on_error, max_errors,
// max_line_length (and for a gins log on the IMU side the rest of the reader's options). Throws InputError
// ("<file>:<line>: <reason>") for input that cannot be converted: damage under the stop policy or beyond
// max_errors, a file that is not its format, no usable fixes or IMU samples, or IMU and GNSS times that do
// not overlap (a different time base: --time-scale?). std::runtime_error when the output cannot be written.
GnssConversion ConvertGnss(const GnssConvertInputs& inputs, const InputOptions& options, const std::string& out_path);

// For a person: records per type, each input's lines and records, what was dropped and ignored, damaged
// lines by reason with the first line of each, warnings, the time span and the leap seconds applied.
std::string FormatGnssConversionSummary(const GnssConversion& conversion);

}  // namespace gins
