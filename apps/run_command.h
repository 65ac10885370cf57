// `gins run`: read the log once, initialise, feed every estimator the same time-ordered measurement stream,
// write each estimator's outputs and the run summary. The command line is a thin shell around this.
#pragma once

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/options.h"
#include "core/eval/trajectory_metrics.h"
#include "solver/session.h"

namespace gins {

struct RunRequest {
  std::string log_path;
  std::string out_dir;
  std::string mode = "eskf";          // eskf | smoother | both
  std::string config_path;            // for the record only
  std::optional<std::string> truth_path;
};

struct RunResult {
  nlohmann::json summary;
  std::vector<std::string> outputs;  // files written
  // Per output stream against the truth, when one was given: the committed output read back and scored
  // like `gins eval` scores it (core/eval/trajectory_metrics.h); summary.json's "accuracy". Streams
  // with nothing to evaluate, or all of them when the comparison failed, are absent.
  std::map<std::string, TrajectoryMetrics> accuracy;
};

// Throws InputError (bad log), RunError (no solution possible) or std::runtime_error (I/O). Nothing is
// left in out_dir when it throws.
RunResult Run(const Options& options, const RunRequest& request);

// The estimator modes Run() accepts.
std::vector<std::string> SupportedModes();

}  // namespace gins
