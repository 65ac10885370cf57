// `gins report`: many runs side by side, one row per run's summary.json (a fleet of logs run with GNU
// parallel or a Slurm array, docs/fleet.md), as a table on stdout and, with --json, a file.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace gins {

struct ReportRequest {
  std::vector<std::string> inputs;  // run directories, summary.json files, or folders holding run directories
  std::string json_path;
};

// Adds the `report` subcommand to `app`, parsing into *req.
CLI::App* AddReportCommand(CLI::App& app, ReportRequest* req);

// One row of the report from a run's summary.json: the log, its duration, the mode, the horizontal RMSE of
// each output against the truth (when the run had one), the measurements rejected (by the estimators and
// refused by the session) and the damaged lines skipped, the watchdog's resets, the real-time factor.
nlohmann::json ReportRow(const std::string& run, const nlohmann::json& summary);

// Prints the table; returns the exit code: 0, or 1 when an input holds no summary (a failed or unfinished
// run: listed as such) or cannot be read (one line on stderr).
int RunReport(const ReportRequest& req);

}  // namespace gins
