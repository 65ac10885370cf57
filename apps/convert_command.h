// `gins convert`: turns logs in other formats into a gins log (docs/formats.md §3, §6). The conversions are in
// the library (core/io/i2nav.h; core/io/gnss_convert.h for rtklib-pos, nmea and csv); this is the command
// line around them.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace gins {

struct ConvertRequest {
  std::string format = "i2nav";  // i2nav | rtklib-pos | nmea | csv
  std::string imu_path;
  std::string gnss_path;
  std::string out_path;
  std::string imu_data = "increments";  // i2nav: increments | rates
  std::string on_error = "skip";        // skip | stop
  int max_errors = 1000;
  int max_line_length = 4096;
  // rtklib-pos, nmea, csv
  std::string time_scale = "gps";  // the log's clock: gps | unix
  std::string min_quality = "single";
  std::string date;             // nmea: YYYY-MM-DD of the first epoch, for files without RMC/ZDA
  double velocity_sigma = 0.1;  // nmea: GVEL horizontal 1-σ, m/s
  std::string gnss_columns, imu_columns, wheel_path, wheel_columns;
};

// Adds the `convert` subcommand to `app`, parsing into *req.
CLI::App* AddConvertCommand(CLI::App& app, ConvertRequest* req);

// Converts; prints a summary on stdout. Returns the exit code: 0 success, 1 bad input or output failure
// (one line on stderr, "gins: error: <file>:<line>: <reason>", and no output file), 2 options that do not
// go with the format.
int RunConvert(const ConvertRequest& req);

}  // namespace gins
