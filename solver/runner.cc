#include "solver/runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/eval/run_comparison.h"
#include "core/geodesy.h"
#include "core/io/batch_pipe.h"
#include "core/io/log_reader.h"
#include "core/io/trajectory_writer.h"
#include "core/io/truth_reader.h"
#include "solver/eskf.h"
#include "solver/session.h"
#include "solver/smoother.h"

namespace gins {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// Writers of one output stream (e.g. "eskf"), created at its first state because the trajectory header
// needs the world frame's origin. It is scored against a truth after the run, from the committed files
// (AddComparison): the same code as `gins eval`, and memory that does not grow with the log.
class OutputStream {
 public:
  OutputStream(const std::string& name, const std::string& dir, const LocalEnuFrame& frame, bool with_states)
      : name_(name), tum_(dir + "/" + name + ".tum", name, frame.origin()) {
    if (with_states) {
      states_ = std::make_unique<StatesCsvWriter>(dir + "/" + name + "_states.csv", name, frame.origin());
    }
  }

  void Add(const StateEstimate& e) {
    if (!e.x.AllFinite() || !e.sigma_p.allFinite() || !e.sigma_v.allFinite() || !e.sigma_att.allFinite() ||
        !std::isfinite(e.odom_scale)) {
      ++non_finite_;  // never written (the writers refuse it too): a NaN must not reach an output
      return;
    }
    if (e.x.t <= last_t_) return;  // one state per time stamp, in time order
    last_t_ = e.x.t;
    tum_.Add(e.x);
    if (states_) states_->Add(e.x, e.sigma_p, e.sigma_v, e.sigma_att, e.odom_scale);
  }

  std::vector<std::string> Commit(const std::string& dir) {
    std::vector<std::string> files;
    tum_.Commit();
    files.push_back(dir + "/" + name_ + ".tum");
    if (states_) {
      states_->Commit();
      files.push_back(dir + "/" + name_ + "_states.csv");
    }
    return files;
  }

  uint64_t count() const { return tum_.count(); }
  uint64_t non_finite() const { return non_finite_; }

 private:
  std::string name_;
  TumWriter tum_;
  std::unique_ptr<StatesCsvWriter> states_;
  uint64_t non_finite_ = 0;
  double last_t_ = -1e300;
};

using Streams = std::map<std::string, std::unique_ptr<OutputStream>>;

void CheckMode(const std::string& mode) {
  const auto modes = SupportedModes();
  if (std::find(modes.begin(), modes.end(), mode) == modes.end()) {
    throw RunError("unknown or unsupported mode '" + mode + "'");
  }
}

// Reads the truth through once, so that a damaged truth stops the run when the first state comes and not
// when the outputs are scored after the whole log.
void CheckTruth(const std::string& path, const LocalEnuFrame& frame) {
  TruthReader reader(path, frame);
  TruthSample x;
  while (reader.Next(&x)) {
  }
}

// Every record of the log to the session, in file order.
void FeedLog(const RunOptions& options, const RunRequest& request, LogReader* reader, Session* session) {
  LogRecord rec;
  while (reader->Next(&rec)) {
    switch (rec.type) {
      case LogRecord::Type::kImu:
        session->AddImu(rec.imu);
        break;
      case LogRecord::Type::kOdom:
        session->AddOdom(rec.odom);
        break;
      case LogRecord::Type::kGnss:
        session->AddGnss(rec.gnss);
        break;
      case LogRecord::Type::kGvel:
        session->AddGvel(rec.gvel);
        break;
    }
    if (!session->initialized() && session->elapsed() > options.init.max_wait) {
      throw RunError(request.log_path + ": not initialised after " + std::to_string(options.init.max_wait) +
                     " s (init.max_wait_s): " + session->Diagnosis());
    }
  }
}

// Fatal input: says what the file held, in one line (what was read, what was damaged and the first why).
void CheckInput(const std::string& log_path, const ReadStats& rs, const Session& session) {
  auto no_usable = [&](const std::string& what) {
    if (rs.lines == 0) return RunError(log_path + ": empty log (no lines)");
    std::string m = log_path + ": no usable " + what + " records (" + std::to_string(rs.lines) + " lines: " +
                    std::to_string(rs.imu) + " IMU, " + std::to_string(rs.odom) + " ODOM, " +
                    std::to_string(rs.gnss) + " GNSS, " +
                    (rs.gvel > 0 ? std::to_string(rs.gvel) + " GVEL, " : std::string()) +
                    std::to_string(rs.total_skipped()) + " damaged";
    if (!rs.examples.empty()) {
      m += "; first: line " + std::to_string(rs.examples.front().line) + ": " + rs.examples.front().reason + ": " +
           rs.examples.front().detail;
    }
    return RunError(m + ")");
  };
  if (rs.imu == 0) throw no_usable("IMU");
  if (rs.gnss == 0) throw no_usable("GNSS");
  if (!session.initialized()) throw RunError(log_path + ": " + session.Diagnosis());
}

// summary.json's "input": what was read and skipped.
nlohmann::json InputJson(const ReadStats& rs, const Session& session, const nlohmann::json& session_stats) {
  nlohmann::json input;
  input["lines"] = rs.lines;
  input["records"] = {{"imu", rs.imu}, {"odom", rs.odom}, {"gnss", rs.gnss}, {"gvel", rs.gvel}};
  input["skipped"] = nlohmann::json::object();
  for (const auto& [k, v] : rs.skipped) input["skipped"][k] = v;
  input["skipped_examples"] = nlohmann::json::array();
  for (const auto& ex : rs.examples) {
    input["skipped_examples"].push_back({{"line", ex.line}, {"reason", ex.reason}, {"detail", ex.detail}});
  }
  // Every damaged line by number (bounded by input.max_errors); the examples above say why.
  input["skipped_lines"] = nlohmann::json::object();
  for (const auto& [k, v] : rs.skipped_lines) input["skipped_lines"][k] = v;
  input["first_time"] = session.first_time();
  input["last_time"] = session.last_time();
  input["odom_ignored_wheel_disabled"] = session_stats["odom_ignored_wheel_disabled"];
  input["gvel_unused"] = session_stats["gvel_unused"];
  input["dropped_before_first_fix"] = session_stats["dropped_before_first_fix"];
  return input;
}

// The summary up to the outputs: the run, its input, the estimators, timing, and the GNSS outage windows
// (simulated ones and the log's own gaps, absolute times) that the comparison scores the drift over.
nlohmann::json RunSummary(const RunOptions& options, const RunRequest& request, const ReadStats& rs,
                          const Session& session, const Streams& streams, Clock::time_point wall_start) {
  nlohmann::json j;
  j["gins_version"] = "0.1.0";
  j["mode"] = request.mode;
  j["config"] = request.config_path;
  j["log"] = request.log_path;
  const GeodeticPoint& origin = session.frame()->origin();
  j["origin_lla"] = {origin.lat_deg, origin.lon_deg, origin.alt_m};
  j["gravity_m_s2"] = session.g_norm();
  const nlohmann::json session_stats = session.Stats();
  j["input"] = InputJson(rs, session, session_stats);
  j["initialization"] = session_stats["initialization"];
  j["estimators"] = session_stats["estimators"];
  const double log_duration = session.last_time() - session.first_time();
  const double wall = Seconds(Clock::now() - wall_start);
  j["timing"] = {{"wall_s", wall},
                 {"log_duration_s", log_duration},
                 {"real_time_factor", wall > 0 ? log_duration / wall : 0.0},
                 {"estimator_s", session_stats["estimator_time_s"]}};
  for (const auto& [name, s] : streams) {
    j["outputs"][name] = {{"states", s->count()}, {"non_finite_skipped", s->non_finite()}};
  }
  j["gnss_outages"] = session_stats["gnss_outages"]["windows"];
  j["gnss_outage_fixes"] = {{"dropped", session_stats["gnss_outages"]["fixes_dropped"]},
                            {"kept_before_initialization",
                             session_stats["gnss_outages"]["fixes_kept_before_initialization"]}};
  j["gnss_gaps"] = session_stats["gnss_outages"]["log_gaps"];
  if (request.truth_path) j["truth"] = *request.truth_path;
  j["gnss_lever_arm_m"] = {options.gnss.lever_b.x(), options.gnss.lever_b.y(), options.gnss.lever_b.z()};
  return j;
}

// The committed outputs read back (core/eval/run_comparison.h): each against the truth, with its drift over
// the summary's outage windows, and the smoother against the ESKF, into j["comparison"]; the scores
// against the truth also into j["accuracy"] and *accuracy. Comparisons exist against the truth and against
// the ESKF: without either (the smoother alone) there is nothing to read back.
void AddComparison(const RunRequest& request, const Session& session, const Streams& streams, nlohmann::json* j,
                   std::map<std::string, TrajectoryMetrics>* accuracy) {
  if (!request.truth_path && !(streams.count("eskf") && streams.size() > 1)) return;
  std::vector<std::string> names;
  for (const auto& [name, s] : streams) names.push_back(name);
  const std::optional<TruthFile> truth =
      request.truth_path ? std::optional<TruthFile>(TruthFile{*request.truth_path, *session.frame()}) : std::nullopt;
  try {
    (*j)["comparison"] = CompareRunOutputs(request.out_dir, names, truth ? &*truth : nullptr,
                                           OutageWindowsFromSummary(*j), session.first_time(), accuracy);
  } catch (const std::exception& e) {
    (*j)["comparison"] = {{"error", e.what()}};  // the outputs stand; only their comparison failed
    accuracy->clear();
    return;
  }
  if (!truth) return;
  for (const std::string& name : names) {
    const auto it = accuracy->find(name);
    (*j)["accuracy"][name] = AccuracyToJson(it == accuracy->end() ? nullptr : &it->second);
  }
}

}  // namespace

std::vector<std::string> SupportedModes() { return {"eskf", "smoother", "both"}; }

RunResult Run(const RunOptions& options, const RunRequest& request) {
  const auto wall_start = Clock::now();
  CheckMode(request.mode);
  LogReader reader(request.log_path, options.input);
  std::error_code ec;
  std::filesystem::create_directories(request.out_dir, ec);
  if (ec) throw std::runtime_error(request.out_dir + ": cannot create output directory: " + ec.message());

  Session session(options);
  bool truth_checked = false;
  Streams streams;
  // Formatting and writing the outputs runs on a second thread, in the order the states come: at IMU rate
  // it costs about as much as the ESKF. Declared after `streams`, so it is joined before they close.
  BatchPipe<std::pair<OutputStream*, StateEstimate>> writer(
      [](const std::pair<OutputStream*, StateEstimate>& item) { item.first->Add(item.second); });
  // States arrive only after initialisation, when the world frame (and so the truth in it) exists.
  auto stream_callback = [&](const std::string& name, bool with_states) {
    return [&, name, with_states](const StateEstimate& e) {
      auto& s = streams[name];
      if (!s) {
        if (request.truth_path && !truth_checked) {
          CheckTruth(*request.truth_path, *session.frame());
          truth_checked = true;
        }
        s = std::make_unique<OutputStream>(name, request.out_dir, *session.frame(), with_states);
      }
      writer.Push({s.get(), e});
    };
  };
  if (request.mode == "eskf" || request.mode == "both") {
    session.AddEstimator(std::make_unique<Eskf>(options, stream_callback("eskf", true)));
  }
  if (request.mode == "smoother" || request.mode == "both") {
    session.AddEstimator(std::make_unique<Smoother>(options, stream_callback("smoother", true),
                                                    stream_callback("smoother_online", false)));
  }

  FeedLog(options, request, &reader, &session);
  CheckInput(request.log_path, reader.stats(), session);
  session.Finish();
  writer.Close();  // every state written (or the writer's error thrown) before the files are committed

  RunResult result;
  for (auto& [name, s] : streams) {
    for (auto& f : s->Commit(request.out_dir)) result.outputs.push_back(f);
  }
  result.summary = RunSummary(options, request, reader.stats(), session, streams, wall_start);
  AddComparison(request, session, streams, &result.summary, &result.accuracy);

  AtomicFile summary(request.out_dir + "/summary.json");
  summary.Write(result.summary.dump(2) + "\n");
  summary.Commit();
  result.outputs.push_back(request.out_dir + "/summary.json");
  return result;
}

}  // namespace gins
