#include "core/eval/run_comparison.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>

#include "core/io/trajectory_reader.h"
#include "core/io/truth_reader.h"

namespace gins {

nlohmann::json MetricsToJson(const TrajectoryMetrics& m, double time_origin) {
  nlohmann::json j;
  j["samples"] = m.samples;
  j["max_gap_s"] = m.max_gap;
  j["reference_samples_in_span"] = m.reference_in_span;
  j["rmse_3d_m"] = m.rmse_3d;
  j["rmse_horizontal_m"] = m.rmse_h;
  j["rmse_vertical_m"] = m.rmse_v;
  j["rmse_east_m"] = m.rmse_e;
  j["rmse_north_m"] = m.rmse_n;
  j["mean_horizontal_m"] = m.mean_h;
  j["max_horizontal_m"] = m.max_h;
  j["max_horizontal_time_s"] = m.t_max_h - time_origin;
  j["rmse_velocity_m_s"] = m.rmse_vel ? nlohmann::json(*m.rmse_vel) : nlohmann::json();
  j["rmse_attitude_deg"] = m.rmse_att_deg;
  j["rmse_heading_deg"] = m.rmse_heading_deg;
  j["max_heading_deg"] = m.max_heading_deg;
  j["attitude_samples"] = m.attitude_samples;
  nlohmann::json rel;
  rel["segment_length_m"] = m.segment_length;
  rel["segments"] = m.segments;
  rel["mean_percent"] = m.segments ? nlohmann::json(m.rel_mean_pct) : nlohmann::json();
  rel["rms_percent"] = m.segments ? nlohmann::json(m.rel_rms_pct) : nlohmann::json();
  rel["max_percent"] = m.segments ? nlohmann::json(m.rel_max_pct) : nlohmann::json();
  j["relative_error"] = rel;
  nlohmann::json outages = nlohmann::json::array();
  for (const OutageDrift& o : m.outages) {
    nlohmann::json x;
    x["begin"] = o.window.begin;
    x["end"] = o.window.end;
    x["begin_s"] = o.window.begin - time_origin;
    x["duration_s"] = o.window.end - o.window.begin;
    x["source"] = o.window.source;
    x["samples"] = o.samples;
    x["max_horizontal_m"] = o.samples ? nlohmann::json(o.max_h) : nlohmann::json();
    x["max_time_s"] = o.samples ? nlohmann::json(o.t_max - time_origin) : nlohmann::json();
    x["final_horizontal_m"] = o.samples ? nlohmann::json(o.final_h) : nlohmann::json();
    outages.push_back(x);
  }
  j["outages"] = outages;
  j["outages_scored"] = m.outages_scored;
  j["outage_drift_rms_m"] = m.outages_scored ? nlohmann::json(m.outage_rms) : nlohmann::json();
  j["outage_drift_max_m"] = m.outages_scored ? nlohmann::json(m.outage_max) : nlohmann::json();
  if (!m.outages.empty()) {
    j["outage_settle_s"] = m.outage_settle;
    j["outside_outages_samples"] = m.outside_samples;
    j["rmse_horizontal_outside_outages_m"] = m.rmse_h_outside ? nlohmann::json(*m.rmse_h_outside) : nlohmann::json();
  }
  nlohmann::json align;
  align["kind"] = AlignmentName(m.alignment);
  if (m.alignment != Alignment::kNone) {
    const Mat3& R = m.align.R;
    align["rotation"] = {R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)};
    align["translation_m"] = {m.align.t.x(), m.align.t.y(), m.align.t.z()};
    align["yaw_deg"] = std::atan2(R(1, 0), R(0, 0)) * kRadToDeg;
  }
  j["alignment"] = align;
  return j;
}

std::vector<TimeWindow> OutageWindowsFromSummary(const nlohmann::json& summary) {
  std::vector<TimeWindow> windows;
  auto add = [&](const char* key, const char* source) {
    if (!summary.contains(key) || !summary[key].is_array()) return;
    for (const auto& w : summary[key]) {
      if (w.is_array() && w.size() == 2 && w[0].is_number() && w[1].is_number()) {
        windows.push_back({w[0].get<double>(), w[1].get<double>(), source});
      }
    }
  };
  add("gnss_outages", "config");
  add("gnss_gaps", "log gap");
  return MergeWindows(windows);
}

std::string StreamFile(const std::string& dir, const std::string& name) {
  const std::filesystem::path d(dir);
  const std::string states = (d / (name + "_states.csv")).string();
  std::error_code ec;
  return std::filesystem::exists(states, ec) ? states : (d / (name + ".tum")).string();
}

namespace {

SampleSource ReaderSource(TrajectoryReader* reader) {
  return [reader](TrajectorySample* s) { return reader->Next(s); };
}

// The gap interpolated across for a trajectory file: a first pass over it for its median interval.
double FileMaxGap(const std::string& path, double max_gap) {
  TrajectoryReader reader(path);
  return EffectiveMaxGap(ReaderSource(&reader), max_gap);
}

struct Outcome {
  std::string name;
  std::optional<TrajectoryMetrics> metrics;
  std::string error;  // why nothing could be evaluated, when !metrics
};

// Each of `names` (files in `files`) against one reference, in a single pass over the reference: every
// estimate is read alongside from its own reader.
std::vector<Outcome> EvaluateAgainst(const SampleSource& reference, bool reference_has_velocity,
                                     const std::vector<std::string>& names,
                                     const std::map<std::string, std::string>& files,
                                     const std::map<std::string, double>& max_gaps, const MetricOptions& options) {
  std::vector<std::unique_ptr<TrajectoryReader>> readers;
  std::vector<TrajectoryEvaluator> evaluators;
  evaluators.reserve(names.size());
  for (const std::string& name : names) {
    readers.push_back(std::make_unique<TrajectoryReader>(files.at(name)));
    TrajectoryReader* reader = readers.back().get();
    evaluators.emplace_back(ReaderSource(reader), reference_has_velocity && reader->has_velocity(),
                            max_gaps.at(name), options);
  }
  TrajectorySample ref;
  while (reference(&ref)) {
    for (TrajectoryEvaluator& e : evaluators) e.AddReference(ref);
  }
  std::vector<Outcome> out;
  for (size_t i = 0; i < names.size(); ++i) {
    Outcome o;
    o.name = names[i];
    try {
      o.metrics = evaluators[i].Metrics();
    } catch (const std::invalid_argument& e) {
      o.error = e.what();
    }
    out.push_back(o);
  }
  return out;
}

// Every output against the truth: j["vs_truth"], j["best_horizontal"], and the metrics into *vs_truth.
void CompareWithTruth(const TruthFile& truth, const std::vector<std::string>& names,
                      const std::map<std::string, std::string>& files, const std::map<std::string, double>& max_gaps,
                      const MetricOptions& options, double time_origin, nlohmann::json* j,
                      std::map<std::string, TrajectoryMetrics>* vs_truth) {
  TruthReader reader(truth.path, truth.frame);
  const SampleSource reference = [&reader](TrajectorySample* s) {
    TruthSample x;
    if (!reader.Next(&x)) return false;
    *s = ToTrajectorySample(x);
    return true;
  };
  double best = 0.0;
  for (const Outcome& o : EvaluateAgainst(reference, true, names, files, max_gaps, options)) {
    if (!o.metrics) {
      (*j)["vs_truth"][o.name] = {{"error", o.error}};
      continue;
    }
    (*j)["vs_truth"][o.name] = MetricsToJson(*o.metrics, time_origin);
    if (vs_truth != nullptr) (*vs_truth)[o.name] = *o.metrics;
    // The causal smoother output is not a competitor of the final one: rank the estimators' main outputs.
    if (o.name != "smoother_online" && (!j->contains("best_horizontal") || o.metrics->rmse_h < best)) {
      best = o.metrics->rmse_h;
      (*j)["best_horizontal"] = o.name;
    }
  }
}

// The outputs other than the ESKF's against it: j["<name>_vs_eskf"].
void CompareWithEskf(const std::vector<std::string>& others, const std::map<std::string, std::string>& files,
                     const std::map<std::string, double>& max_gaps, const MetricOptions& options, double time_origin,
                     nlohmann::json* j) {
  TrajectoryReader eskf(files.at("eskf"));
  for (const Outcome& o : EvaluateAgainst(ReaderSource(&eskf), eskf.has_velocity(), others, files, max_gaps, options)) {
    if (!o.metrics) {
      (*j)[o.name + "_vs_eskf"] = {{"error", o.error}};
      continue;
    }
    const TrajectoryMetrics& m = *o.metrics;
    nlohmann::json d;
    d["samples"] = m.samples;
    d["rms_horizontal_difference_m"] = m.rmse_h;
    d["max_horizontal_difference_m"] = m.max_h;
    d["max_horizontal_difference_time_s"] = m.t_max_h - time_origin;
    d["rms_vertical_difference_m"] = m.rmse_v;
    d["rms_heading_difference_deg"] = m.rmse_heading_deg;
    d["rms_attitude_difference_deg"] = m.rmse_att_deg;
    if (m.rmse_vel) d["rms_velocity_difference_m_s"] = *m.rmse_vel;
    if (m.outages_scored) d["largest_horizontal_difference_in_outages_m"] = m.outage_max;
    (*j)[o.name + "_vs_eskf"] = d;
  }
}

}  // namespace

nlohmann::json AccuracyToJson(const TrajectoryMetrics* m) {
  auto number = [m](double v) { return m ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json j;
  j["samples"] = m ? m->samples : 0;
  j["rmse_3d_m"] = number(m ? m->rmse_3d : 0.0);
  j["rmse_horizontal_m"] = number(m ? m->rmse_h : 0.0);
  j["rmse_vertical_m"] = number(m ? m->rmse_v : 0.0);
  j["max_horizontal_m"] = number(m ? m->max_h : 0.0);
  j["rmse_velocity_m_s"] = m && m->rmse_vel ? nlohmann::json(*m->rmse_vel) : nlohmann::json();
  j["rmse_heading_deg"] = number(m ? m->rmse_heading_deg : 0.0);
  j["rmse_attitude_deg"] = number(m ? m->rmse_att_deg : 0.0);
  j["attitude_samples"] = m ? m->attitude_samples : 0;
  return j;
}

nlohmann::json CompareRunOutputs(const std::string& out_dir, const std::vector<std::string>& streams,
                                 const TruthFile* truth, const std::vector<TimeWindow>& outages, double time_origin,
                                 std::map<std::string, TrajectoryMetrics>* vs_truth) {
  nlohmann::json j;
  MetricOptions options;  // also for the differences from the ESKF: over the whole run, outages included
  options.outages = outages;
  // In name order (eskf, smoother, smoother_online), which also breaks ties of best_horizontal.
  std::map<std::string, std::string> files;
  for (const std::string& name : streams) files[name] = StreamFile(out_dir, name);
  std::vector<std::string> names, others;  // others: all but the ESKF
  for (const auto& [name, file] : files) {
    names.push_back(name);
    if (name != "eskf") others.push_back(name);
  }
  // The outputs evaluated as estimates: all of them against the truth, the others against the ESKF.
  const bool with_eskf = files.count("eskf") && !others.empty();
  std::map<std::string, double> max_gaps;
  for (const std::string& name : names) {
    if (truth != nullptr || (with_eskf && name != "eskf")) max_gaps[name] = FileMaxGap(files.at(name), options.max_gap);
  }
  if (truth != nullptr) CompareWithTruth(*truth, names, files, max_gaps, options, time_origin, &j, vs_truth);
  if (with_eskf) CompareWithEskf(others, files, max_gaps, options, time_origin, &j);
  return j;
}

}  // namespace gins
