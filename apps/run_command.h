// `gins run`: a log through the public API (gins/gins.h, the same path as any user's program) into files:
// each estimator's outputs, written on a second thread, and the run summary with the comparison against a
// truth. The command line is a thin shell around this; `gins stream` shares its input checks and the rule
// for which states an output holds.
#pragma once

#include <cmath>
#include <cstdint>

#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/options.h"
#include "core/eval/trajectory_metrics.h"
#include "core/io/log_reader.h"
#include "gins/gins.h"
#include "solver/estimator.h"
#include "solver/estimator_pipeline.h"

namespace gins {

struct RunRequest {
  std::string log_path;
  std::string out_dir;
  std::string mode = "eskf";          // eskf | smoother | both
  std::string config_path;            // for the record only
  std::optional<std::string> truth_path;
  // Optional: each state an output file holds, as it is written (after StateFilter; State::lla is NaN), on
  // the writer thread, each stream's in time order. The Python package keeps them in memory this way.
  std::function<void(const api::State&)> on_output_state;
  // Optional: called on Run's own thread every 4096 records read and once before the files are committed;
  // an exception it throws stops the run there (nothing is committed) and leaves Run as it is. The Python
  // package checks for Ctrl-C this way.
  std::function<void()> poll;
};

struct RunResult {
  nlohmann::json summary;
  std::vector<std::string> outputs;  // files written
  // Per output stream against the truth, when one was given: the committed output read back and scored
  // like `gins eval` scores it (core/eval/trajectory_metrics.h); summary.json's "accuracy". Streams
  // with nothing to evaluate, or all of them when the comparison failed, are absent.
  std::map<std::string, TrajectoryMetrics> accuracy;
};

// Throws api::Error (a log that cannot be read or is too damaged), RunError (no solution possible) or
// std::runtime_error (I/O). Nothing is left in out_dir when it throws.
RunResult Run(const api::Config& config, const RunRequest& request);

// The estimator modes Run() accepts.
std::vector<std::string> SupportedModes();

// --- Shared with `gins stream` --------------------------------------------------------------------------------

// Which states an output holds: finite ones only (a NaN must not reach an output; the others are counted),
// one per time stamp, in time order.
class StateFilter {
 public:
  bool Accept(const StateEstimate& e) {
    if (!e.x.AllFinite() || !e.sigma_p.allFinite() || !e.sigma_v.allFinite() || !e.sigma_att.allFinite() ||
        !std::isfinite(e.odom_scale)) {
      ++non_finite_;  // never written (the writers refuse it too): a NaN must not reach an output
      return false;
    }
    if (e.x.t <= last_t_) return false;
    last_t_ = e.x.t;
    return true;
  }
  uint64_t non_finite() const { return non_finite_; }

 private:
  uint64_t non_finite_ = 0;
  double last_t_ = -1e300;
};

// After each record: the session gave up waiting for an initialisation (max_wait: init.max_wait_s) is a
// RunError naming the log (`name`).
void CheckInitTimeout(const std::string& name, double max_wait, const api::Session& session);
// At the end of the data: a log without usable IMU or GNSS records, said in one line (what it held and its
// first damaged line; raw_gnss: no GNSS records needed, raw observations stand in). Throws RunError.
void CheckReadCounts(const std::string& name, const ReadStats& rs, bool raw_gnss);
// Finish() on the session; a session that never initialised is a RunError naming the log.
void FinishSession(const std::string& name, api::Session* session);

}  // namespace gins
