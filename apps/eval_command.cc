#include "apps/eval_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/eval/run_comparison.h"
#include "core/eval/trajectory_metrics.h"
#include "core/io/log_reader.h"
#include "core/io/trajectory_reader.h"
#include "core/io/trajectory_writer.h"

namespace gins {
namespace {

namespace fs = std::filesystem;

// Usage problems found after parsing (exit code 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The outputs of a run directory, in a fixed order: every <name>.tum, as <name>_states.csv when present.
std::vector<std::string> RunDirectoryOutputs(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string file = e.path().filename().string();
    if (e.is_regular_file() && file.size() > 4 && file.compare(file.size() - 4, 4, ".tum") == 0) {
      names.push_back(file.substr(0, file.size() - 4));
    }
  }
  // eskf, smoother, smoother_online, then others alphabetically.
  const std::vector<std::string> order = {"eskf", "smoother", "smoother_online"};
  auto rank = [&](const std::string& n) {
    const auto it = std::find(order.begin(), order.end(), n);
    return it == order.end() ? order.size() : static_cast<size_t>(it - order.begin());
  };
  std::sort(names.begin(), names.end(),
            [&](const std::string& a, const std::string& b) { return std::make_pair(rank(a), a) < std::make_pair(rank(b), b); });
  std::vector<std::string> files;
  for (const auto& n : names) files.push_back(StreamFile(dir, n));
  if (files.empty()) throw InputError(dir + ": no trajectories (*.tum) in this directory");
  return files;
}

// A short row label: the mode named in the header, else the file name without extensions and "_states".
std::string Label(const Trajectory& t) {
  if (!t.mode.empty()) return t.mode;
  std::string name = fs::path(t.path).filename().string();
  for (const char* ext : {".gz", ".csv", ".tum", ".txt"}) {
    const std::string e = ext;
    if (name.size() > e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0) {
      name.erase(name.size() - e.size());
    }
  }
  const std::string states = "_states";
  if (name.size() > states.size() && name.compare(name.size() - states.size(), states.size(), states) == 0) {
    name.erase(name.size() - states.size());
  }
  return name;
}

std::string Num(double v, int decimals) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

std::string Num(const std::optional<double>& v, int decimals) { return v ? Num(*v, decimals) : "-"; }

nlohmann::json ReadJsonFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open summary");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not a JSON run summary: " + e.what());
  }
}

// Rigid transform of truth samples from one ENU frame into another (see ChangeFrame).
void TruthChangeFrame(const LocalEnuFrame& from, const LocalEnuFrame& to, std::vector<TruthSample>* truth) {
  const Mat3 R = to.RotationFromLocalEnu(from.origin());
  const Quat q(R);
  const Vec3 o = to.ToEnu(from.origin());
  for (TruthSample& s : *truth) {
    s.p_w = R * s.p_w + o;
    s.q_wb = (q * s.q_wb).normalized();
    s.v_w = R * s.v_w;
  }
}

struct Row {
  std::string label;
  std::string path;
  bool has_velocity = false;
  TrajectoryMetrics m;
};

void PrintTable(const std::string& reference, const std::string& frame_text, Alignment alignment,
                const std::vector<Row>& rows, const std::vector<TimeWindow>& outages, double time_origin,
                double segment_length) {
  size_t w = 10;
  for (const Row& r : rows) w = std::max(w, r.label.size() + 1);
  std::printf("gins eval: against %s; %s; alignment %s\n", reference.c_str(), frame_text.c_str(),
              AlignmentName(alignment).c_str());
  std::printf("%-*s %8s %8s %8s %8s %8s %9s %9s %9s %9s %9s %9s\n", static_cast<int>(w), "", "samples", "3D RMSE",
              "H RMSE", "V RMSE", "H max", "vel RMSE", "att RMSE", "hdg RMSE", "rel err", "outage", "outage");
  char rel_unit[32];
  std::snprintf(rel_unit, sizeof(rel_unit), "%%/%gm", segment_length);
  std::printf("%-*s %8s %8s %8s %8s %8s %9s %9s %9s %9s %9s %9s\n", static_cast<int>(w), "", "", "m", "m", "m", "m",
              "m/s", "deg", "deg", rel_unit, "RMS m", "max m");
  for (const Row& r : rows) {
    const TrajectoryMetrics& m = r.m;
    std::printf("%-*s %8llu %8s %8s %8s %8s %8s %9s %9s %9s %9s %9s\n", static_cast<int>(w), r.label.c_str(),
                static_cast<unsigned long long>(m.samples), Num(m.rmse_3d, 3).c_str(), Num(m.rmse_h, 3).c_str(),
                Num(m.rmse_v, 3).c_str(), Num(m.max_h, 3).c_str(), Num(m.rmse_vel, 3).c_str(),
                Num(m.rmse_att_deg, 3).c_str(), Num(m.rmse_heading_deg, 3).c_str(),
                m.segments ? Num(m.rel_mean_pct, 3).c_str() : "-",
                m.outages_scored ? Num(m.outage_rms, 3).c_str() : "-",
                m.outages_scored ? Num(m.outage_max, 3).c_str() : "-");
  }
  if (outages.empty()) return;
  std::printf("\nGNSS outages (s after the first record): largest horizontal drift, m\n");
  std::printf("  %2s %8s %6s %-16s", "#", "begin", "length", "source");
  for (const Row& r : rows) std::printf(" %*s", static_cast<int>(std::max<size_t>(9, r.label.size())), r.label.c_str());
  std::printf("\n");
  for (size_t i = 0; i < outages.size(); ++i) {
    std::printf("  %2zu %8.1f %6.1f %-16s", i + 1, outages[i].begin - time_origin, outages[i].end - outages[i].begin,
                outages[i].source.c_str());
    for (const Row& r : rows) {
      const OutageDrift& o = r.m.outages[i];
      std::printf(" %*s", static_cast<int>(std::max<size_t>(9, r.label.size())),
                  o.samples ? Num(o.max_h, 3).c_str() : "-");
    }
    std::printf("\n");
  }
  std::printf("  %2s %8s %6s %-16s", "", "", "", "RMS");
  for (const Row& r : rows) {
    std::printf(" %*s", static_cast<int>(std::max<size_t>(9, r.label.size())),
                r.m.outages_scored ? Num(r.m.outage_rms, 3).c_str() : "-");
  }
  std::printf("\n");
  // The accuracy with GNSS, not hidden by the drift without it.
  std::printf("  H RMSE outside outages and %g s after each, m\n  %2s %8s %6s %-16s", rows.front().m.outage_settle, "",
              "", "", "");
  for (const Row& r : rows) {
    std::printf(" %*s", static_cast<int>(std::max<size_t>(9, r.label.size())),
                r.m.rmse_h_outside ? Num(*r.m.rmse_h_outside, 4).c_str() : "-");
  }
  std::printf("\n");
}

// The files to evaluate: the inputs, run directories expanded to their outputs. A run directory's summary
// becomes *summary_path unless one was given.
std::vector<std::string> ExpandInputs(const std::vector<std::string>& inputs, std::string* summary_path) {
  std::vector<std::string> files;
  for (const std::string& in : inputs) {
    std::error_code ec;
    if (fs::is_directory(in, ec)) {
      for (const auto& f : RunDirectoryOutputs(in)) files.push_back(f);
      if (summary_path->empty() && fs::exists(in + "/summary.json", ec)) *summary_path = in + "/summary.json";
    } else {
      files.push_back(in);
    }
  }
  return files;
}

// The trajectories and the truth (when given) in one evaluation frame: the first trajectory's origin, else
// the truth's first row. Returns the frame (none without either), and whether a file without an origin was
// taken to be in it.
struct Inputs {
  std::vector<Trajectory> traj;
  std::vector<TruthSample> truth;
  std::optional<LocalEnuFrame> frame;
  bool assumed_frame = false;
};

Inputs ReadInFrame(const std::vector<std::string>& files, const std::string& truth_path) {
  Inputs in;
  for (const std::string& f : files) in.traj.push_back(ReadTrajectory(f));
  for (const Trajectory& t : in.traj) {
    if (t.origin) {
      in.frame.emplace(*t.origin);
      break;
    }
  }
  if (!truth_path.empty()) {
    if (in.frame) {
      in.truth = ReadTruth(truth_path, *in.frame);
    } else {
      const LocalEnuFrame earth_centre({0.0, 0.0, 0.0});
      in.truth = ReadTruth(truth_path, earth_centre);
      in.frame.emplace(earth_centre.ToGeodetic(in.truth.front().p_w));
      TruthChangeFrame(earth_centre, *in.frame, &in.truth);
    }
  }
  for (Trajectory& t : in.traj) {
    if (t.origin && in.frame) {
      ChangeFrame(LocalEnuFrame(*t.origin), *in.frame, &t);
    } else if (!t.origin) {
      in.assumed_frame = true;  // a foreign file: taken to be in the evaluation frame already
    }
  }
  return in;
}

// Short labels, unique (the path where two would be the same).
std::vector<std::string> Labels(const std::vector<Trajectory>& traj) {
  std::vector<std::string> labels;
  for (const Trajectory& t : traj) labels.push_back(Label(t));
  for (size_t i = 0; i < labels.size(); ++i) {
    if (std::count(labels.begin(), labels.end(), labels[i]) > 1) labels[i] = traj[i].path;
  }
  return labels;
}

std::string FrameText(const std::optional<LocalEnuFrame>& frame, bool assumed_frame) {
  std::string text = "frame ENU";
  if (frame) {
    char buf[128];
    std::snprintf(buf, sizeof(buf), "frame ENU at %.7f %.7f %.3f", frame->origin().lat_deg, frame->origin().lon_deg,
                  frame->origin().alt_m);
    text = buf;
  }
  if (assumed_frame) text += " (files without an origin taken to be in it)";
  return text;
}

// The --json file: every metric, per-outage lists included.
void WriteJson(const EvalRequest& req, const Inputs& in, size_t reference_samples, const std::string& summary_path,
               const std::vector<TimeWindow>& outages, double time_origin, Alignment alignment,
               const std::vector<Row>& rows) {
  const bool with_truth = !req.truth_path.empty();
  nlohmann::json j;
  j["reference"] = {{"kind", with_truth ? "truth" : "trajectory"},
                    {"path", with_truth ? req.truth_path : in.traj.front().path},
                    {"samples", reference_samples}};
  if (in.frame) {
    j["frame_origin_lla"] = {in.frame->origin().lat_deg, in.frame->origin().lon_deg, in.frame->origin().alt_m};
  }
  j["time_origin"] = time_origin;
  j["summary"] = summary_path.empty() ? nlohmann::json() : nlohmann::json(summary_path);
  j["alignment"] = AlignmentName(alignment);
  j["segment_length_m"] = req.segment_length;
  j["max_gap_s"] = req.max_gap;
  nlohmann::json ow = nlohmann::json::array();
  for (const TimeWindow& w : outages) {
    ow.push_back({{"begin", w.begin}, {"end", w.end}, {"begin_s", w.begin - time_origin}, {"source", w.source}});
  }
  j["outage_windows"] = ow;
  j["trajectories"] = nlohmann::json::array();
  for (const Row& r : rows) {
    nlohmann::json t = MetricsToJson(r.m, time_origin);
    t["name"] = r.label;
    t["path"] = r.path;
    t["has_velocity"] = r.has_velocity;
    j["trajectories"].push_back(t);
  }
  const fs::path parent = fs::path(req.json_path).parent_path();
  std::error_code ec;
  if (!parent.empty()) fs::create_directories(parent, ec);
  AtomicFile out(req.json_path);
  out.Write(j.dump(2) + "\n");
  out.Commit();
  std::printf("\nwrote %s\n", req.json_path.c_str());
}

int Evaluate(const EvalRequest& req) {
  if (req.segment_length <= 0.0) throw UsageError("--segment-length must be > 0");
  if (req.max_gap <= 0.0) throw UsageError("--max-gap must be > 0");
  const Alignment alignment = ParseAlignment(req.align);

  // Inputs: files, or run directories (their outputs, and their summary unless --summary is given).
  std::string summary_path = req.summary_path;
  const std::vector<std::string> files = ExpandInputs(req.inputs, &summary_path);
  const bool with_truth = !req.truth_path.empty();
  if (!with_truth && files.size() < 2) {
    throw UsageError("give --truth FILE, or at least two trajectories (the first is the reference)");
  }
  const Inputs in = ReadInFrame(files, req.truth_path);
  const std::vector<std::string> labels = Labels(in.traj);

  std::vector<TimeWindow> outages;
  double time_origin = with_truth ? in.truth.front().t : in.traj.front().samples.front().t;
  if (!summary_path.empty()) {
    const nlohmann::json summary = ReadJsonFile(summary_path);
    outages = OutageWindowsFromSummary(summary);
    if (summary.contains("input") && summary["input"].contains("first_time") &&
        summary["input"]["first_time"].is_number()) {
      time_origin = summary["input"]["first_time"].get<double>();
    }
  }

  MetricOptions options;
  options.max_gap = req.max_gap;
  options.segment_length = req.segment_length;
  options.alignment = alignment;
  options.outages = outages;
  options.outage_settle = req.outage_settle;

  // The reference: the truth, else the first trajectory (then not an estimate).
  const std::vector<TrajectorySample> reference =
      with_truth ? ToTrajectorySamples(in.truth) : in.traj.front().samples;
  const bool reference_velocity = with_truth || in.traj.front().has_velocity;
  const std::string reference_text = with_truth ? "truth " + req.truth_path
                                                : labels.front() + " (" + in.traj.front().path + ")";
  std::vector<Row> rows;
  for (size_t i = with_truth ? 0 : 1; i < in.traj.size(); ++i) {
    Row r;
    r.label = labels[i];
    r.path = in.traj[i].path;
    r.has_velocity = in.traj[i].has_velocity;
    try {
      r.m = EvaluateTrajectory(reference, reference_velocity, in.traj[i].samples, in.traj[i].has_velocity, options);
    } catch (const std::invalid_argument& e) {
      throw InputError(in.traj[i].path + ": " + e.what());
    }
    rows.push_back(r);
  }

  PrintTable(reference_text, FrameText(in.frame, in.assumed_frame), alignment, rows, outages, time_origin,
             req.segment_length);
  if (!req.json_path.empty()) {
    WriteJson(req, in, reference.size(), summary_path, outages, time_origin, alignment, rows);
  }
  return 0;
}

}  // namespace

CLI::App* AddEvalCommand(CLI::App& app, EvalRequest* req) {
  auto* eval = app.add_subcommand(
      "eval",
      "Accuracy of trajectories against a truth (--truth), or of estimates against the first one: RMSE 3-D, "
      "horizontal, vertical, velocity, attitude, heading; relative error over distance; drift over GNSS outages");
  eval->add_option("trajectories", req->inputs,
                   "Trajectories: our .tum or *_states.csv (its origin from the .tum beside it; .gz too), foreign TUM, or run "
                   "directories (their outputs and summary.json)")
      ->required();
  eval->add_option("--truth", req->truth_path, "Truth CSV (docs/formats.md §4; .gz too)")->check(CLI::ExistingFile);
  eval->add_option("--summary", req->summary_path,
                   "A run's summary.json: score the drift over its GNSS outages (simulated and log gaps)")
      ->check(CLI::ExistingFile);
  eval->add_option("--json", req->json_path, "Write every metric, per-outage lists included, to this JSON file");
  eval->add_option("--align", req->align,
                   "Alignment before scoring, for inputs that are not geo-referenced: none, yaw (4-DoF: yaw + "
                   "translation) or se3 (Umeyama, no scale)")
      ->check(CLI::IsMember({"none", "yaw", "se3"}))
      ->capture_default_str();
  eval->add_option("--segment-length", req->segment_length, "Travelled distance of the relative-error segments (m)")
      ->capture_default_str();
  eval->add_option("--outage-settle", req->outage_settle,
                   "Time after each GNSS outage (s) also left out of the horizontal RMSE outside outages")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  eval->add_option("--max-gap", req->max_gap,
                   "Largest estimate gap interpolated across (s); at least 3x the estimate's median interval")
      ->capture_default_str();
  return eval;
}

int RunEval(const EvalRequest& req) {
  try {
    return Evaluate(req);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "gins eval: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gins: error: %s\n", e.what());
    return 1;
  }
}

}  // namespace gins
