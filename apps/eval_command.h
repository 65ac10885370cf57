// `gins eval`: accuracy of trajectories against a truth (docs/formats.md §4), or of estimates against each other,
// with the metrics of core/trajectory_metrics.h: a table on stdout, everything as JSON with --json.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace gins {

struct EvalRequest {
  std::vector<std::string> inputs;  // trajectory files (TUM or *_states.csv, .gz too) or run directories
  std::string truth_path;           // empty: the first input is the reference
  std::string summary_path;         // a run's summary.json: its GNSS outage windows are scored
  std::string json_path;
  std::string align = "none";       // none | yaw | se3
  double segment_length = 100.0;    // m, relative error
  double max_gap = 1.0;             // s, largest estimate gap interpolated across
  double outage_settle = 5.0;       // s after each outage also left out of the RMSE outside outages
};

// Adds the `eval` subcommand to `app`, parsing into *req.
CLI::App* AddEvalCommand(CLI::App& app, EvalRequest* req);

// Runs an evaluation; returns the exit code (0 success, 1 bad input, 2 usage error). Messages go to
// stderr as "gins: error: ...".
int RunEval(const EvalRequest& req);

}  // namespace gins
