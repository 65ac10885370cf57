// `gins convert`: turns logs in other formats into a gins log (docs/formats.md §3). The conversion itself is in the
// library (core/io/i2nav.h); this is the command line around it.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace gins {

struct ConvertRequest {
  std::string format = "i2nav";
  std::string imu_path;
  std::string gnss_path;
  std::string out_path;
  std::string imu_data = "increments";  // increments | rates
  std::string on_error = "skip";        // skip | stop
  int max_errors = 1000;
  int max_line_length = 4096;
};

// Adds the `convert` subcommand to `app`, parsing into *req.
CLI::App* AddConvertCommand(CLI::App& app, ConvertRequest* req);

// Converts; prints a summary on stdout. Returns the exit code: 0 success, 1 bad input or output failure
// (one line on stderr, "gins: error: <file>:<line>: <reason>", and no output file).
int RunConvert(const ConvertRequest& req);

}  // namespace gins
