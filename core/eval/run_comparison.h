// Comparing estimators' outputs with each other and with a truth, with the metrics of
// core/eval/trajectory_metrics.h: the end of `gins run` (summary.json's "comparison" and "accuracy") and
// `gins eval` share this JSON form.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/eval/trajectory_metrics.h"
#include "core/geodesy.h"

namespace gins {

// One trajectory's metrics; times also relative to `time_origin` (the log's first record) for reading.
nlohmann::json MetricsToJson(const TrajectoryMetrics& m, double time_origin);

// summary.json's short "accuracy.<stream>" form of the same metrics (keys as in MetricsToJson: samples,
// rmse_3d_m, rmse_horizontal_m, rmse_vertical_m, max_horizontal_m, rmse_velocity_m_s, rmse_heading_deg,
// rmse_attitude_deg, attitude_samples: the pairs where both have a yaw). Null `m` (nothing evaluated): samples 0 and null numbers rather than zeros, which
// would read as a perfect score.
nlohmann::json AccuracyToJson(const TrajectoryMetrics* m);

// The outage windows a run summary records: the simulated ones ("gnss_outages", source "config") and the
// log's own GNSS gaps ("gnss_gaps", source "log gap"), merged where they overlap. Empty when the summary
// has neither.
std::vector<TimeWindow> OutageWindowsFromSummary(const nlohmann::json& summary);

// The output file of a stream in a run directory: <name>_states.csv when it exists (it has velocities),
// else <name>.tum.
std::string StreamFile(const std::string& dir, const std::string& name);

// A run's truth file, read in the run's world frame.
struct TruthFile {
  std::string path;
  LocalEnuFrame frame;
};

// After a run, from the committed outputs in `out_dir` (all in the run's world frame): each stream against
// the truth (when given) with drift over `outages`, and the other streams' differences from the ESKF when
// it ran. Returns {"vs_truth": {name: metrics}, "<name>_vs_eskf": {...}, "best_horizontal": name}; the
// streams evaluated against the truth also go into *vs_truth when given (the run's "accuracy").
// Every file is streamed (TrajectoryEvaluator), so memory does not grow with the run's length: a first pass
// over each output for its median interval, then one pass over the truth with every output read alongside,
// and one over the ESKF's output with the others alongside.
nlohmann::json CompareRunOutputs(const std::string& out_dir, const std::vector<std::string>& streams,
                                 const TruthFile* truth, const std::vector<TimeWindow>& outages, double time_origin,
                                 std::map<std::string, TrajectoryMetrics>* vs_truth = nullptr);

}  // namespace gins
