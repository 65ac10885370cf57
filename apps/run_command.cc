#include "apps/run_command.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "apps/api/access.h"
#include "apps/api/convert.h"
#include "core/eval/run_comparison.h"
#include "core/geodesy.h"
#include "core/io/batch_pipe.h"
#include "core/io/read_ahead.h"
#include "core/io/trajectory_writer.h"
#include "core/io/truth_reader.h"
#include "solver/health.h"
#include "solver/summary_keys.h"

namespace gins {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// Writers of one output stream (e.g. "eskf"), created at its first state because the trajectory header
// needs the world frame's origin: its TUM file, its states CSV (all but smoother_online) and its geodetic
// track. It is scored against a truth after the run, from the committed files (AddComparison): the same
// code as `gins eval`, and memory that does not grow with the log.
class OutputStream {
 public:
  OutputStream(const std::string& name, const std::string& dir, const LocalEnuFrame& frame, bool with_states)
      : name_(name), tum_(dir + "/" + name + ".tum", name, frame.origin()),
        lla_(dir + "/" + name + "_lla.csv", frame) {
    if (with_states) states_ = std::make_unique<StatesCsvWriter>(dir + "/" + name + "_states.csv");
  }

  void Add(const StateEstimate& e) {
    if (filter_.Accept(e)) tum_.AddWithStates(states_.get(), &lla_, e.x, e.sigma_p, e.sigma_v, e.sigma_att, e.odom_scale);
  }

  std::vector<std::string> Commit(const std::string& dir) {
    std::vector<std::string> files;
    tum_.Commit();
    files.push_back(dir + "/" + name_ + ".tum");
    if (states_) {
      states_->Commit();
      files.push_back(dir + "/" + name_ + "_states.csv");
    }
    lla_.Commit();
    files.push_back(dir + "/" + name_ + "_lla.csv");
    return files;
  }

  uint64_t count() const { return tum_.count(); }
  uint64_t non_finite() const { return filter_.non_finite(); }

 private:
  std::string name_;
  TumWriter tum_;
  std::unique_ptr<StatesCsvWriter> states_;
  GeodeticCsvWriter lla_;
  StateFilter filter_;
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

std::string AbsolutePath(const std::string& path) {
  if (path.empty()) return path;
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::absolute(path, ec);
  return ec ? path : p.lexically_normal().string();
}

// summary.json's "input": what was read and skipped.
nlohmann::json InputJson(const ReadStats& rs, const EstimatorPipeline& session, const nlohmann::json& session_stats,
                         const api::Status& status) {
  nlohmann::json input;
  input["lines"] = rs.lines;
  input["records"] = nlohmann::json::object();
  for (size_t k = 0; k < kNumRecordTypes; ++k) input["records"][kRecordTypes[k].count_key] = rs.records[k];
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
  namespace k = summary_keys;
  for (const char* key : {k::kOdomIgnoredWheelDisabled, k::kGvelUnused, k::kDroppedBeforeFirstFix,
                          k::kRestStatesBeforeInitialization}) {
    input[key] = session_stats.at(key);
  }
  // The API's reorder buffer (input.reorder_window_s): records sorted into place, and those refused (a
  // log's late records are out_of_order damage above, so "refused" stays empty for a log).
  nlohmann::json refused = nlohmann::json::object();
  for (const api::Rejection& r : status.rejections) {
    if (r.source == "input") refused[r.measurement][r.reason] = r.count;
  }
  const nlohmann::json& api_session = session_stats.at(k::kSession);
  input["reorder"] = {{"window_s", api_session.at(k::kReorderWindow)}, {"sorted", status.reordered}};
  input["stamps"] = api_session.at(k::kStamps);  // input.regularize_stamps
  input["refused"] = refused;
  return input;
}

// summary.json's "faults": every fault the run met, counted in one place (the details stay where they are:
// input.skipped, estimators.<name>.*): damaged or out-of-order lines by reason, IMU gaps, interval jitter,
// rate changes and repeated stamps, wheel jitter and gaps, GNSS gaps, and per estimator the measurements
// rejected, the watchdog's re-initialisations and the output states skipped as not finite.
nlohmann::json FaultsJson(const nlohmann::json& summary, const nlohmann::json& session_stats) {
  nlohmann::json f;
  f["input_skipped"] = summary["input"]["skipped"];
  namespace k = summary_keys;
  for (const char* key :
       {k::kImuIntervalJitter, k::kImuRateChanges, k::kImuSameStamp, k::kWheelIntervalJitter, k::kWheelGaps}) {
    f[key] = session_stats.at(key);
  }
  f["gnss_gaps"] = summary["gnss_gaps"].size();
  f["estimators"] = nlohmann::json::object();
  for (const auto& [name, e] : summary["estimators"].items()) {
    nlohmann::json r = nlohmann::json::object();
    for (const auto& [type, counts] : e.items()) {
      if (counts.is_object() && counts.contains("rejected")) {
        uint64_t n = 0;
        for (const auto& [reason, c] : counts["rejected"].items()) n += c.get<uint64_t>();
        if (n > 0) r[type] = n;
      }
    }
    f["estimators"][name] = {
        {"imu_gaps", e.at(k::kImuGaps)},
        {"rejected", r},
        {"watchdog_resets", e.contains(k::kWatchdog) ? e[k::kWatchdog].at(k::kWatchdogCount) : nlohmann::json(0)}};
  }
  for (const auto& [name, o] : summary["outputs"].items()) {
    f["non_finite_skipped"][name] = o.value("non_finite_skipped", 0);
  }
  return f;
}

// The summary up to the outputs: the run, its input, the estimators, timing, and the GNSS outage windows
// (simulated ones and the log's own gaps, absolute times) that the comparison scores the drift over.
nlohmann::json RunSummary(const Options& options, const RunRequest& request, const ReadStats& rs,
                          const api::Session& api_session, const Streams& streams, Clock::time_point wall_start) {
  const EstimatorPipeline& session = api::internal::Access::session(api_session);
  nlohmann::json j;
  j["gins_version"] = api::Version();
  j["mode"] = request.mode;
  // Absolute, so that the summary's readers (gins eval --summary, plot_run.py) find them from any folder.
  j["config"] = AbsolutePath(request.config_path);
  j["log"] = AbsolutePath(request.log_path);
  const GeodeticPoint& origin = session.frame()->origin();
  j["origin_lla"] = {origin.lat_deg, origin.lon_deg, origin.alt_m};
  j["gravity_m_s2"] = session.g_norm();
  const nlohmann::json session_stats = api::internal::Access::stats(api_session);
  j["input"] = InputJson(rs, session, session_stats, api_session.status());
  j["initialization"] = session_stats["initialization"];
  if (session_stats.contains("gnss_raw")) j["gnss_raw"] = session_stats["gnss_raw"];
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
  if (request.truth_path) j["truth"] = AbsolutePath(*request.truth_path);
  const Vec3& lever = options.sensors.gnss.lever_b;
  j["gnss_lever_arm_m"] = {lever.x(), lever.y(), lever.z()};
  j["faults"] = FaultsJson(j, session_stats);
  if (session_stats.contains("warnings")) j["warnings"] = session_stats["warnings"];
  if (session_stats.contains("turn_rate_check")) j["input"]["turn_rate_check"] = session_stats["turn_rate_check"];
  if (session_stats.contains("heading_check")) j["input"]["heading_check"] = session_stats["heading_check"];
  if (session_stats.contains("clock_check")) j["input"]["clock_check"] = session_stats["clock_check"];
  // Each estimator's verdict (solver/health.h), its outputs' dropped states included.
  for (const auto& [name, est] : j["estimators"].items()) {
    uint64_t non_finite = 0;
    for (const auto& [stream, s] : streams) {
      // eskf and eskf_rts are the ESKF's; smoother, smoother_online and batch the smoother's.
      if ((stream.rfind("eskf", 0) == 0) == (name == "eskf")) non_finite += s->non_finite();
    }
    j["health"][name] = JudgeHealth(est, non_finite).ToJson();
  }
  return j;
}

// The committed outputs read back (core/eval/run_comparison.h): each against the truth, with its drift over
// the summary's outage windows, and the smoother against the ESKF, into j["comparison"]; the scores
// against the truth also into j["accuracy"] and *accuracy. Comparisons exist against the truth and against
// the ESKF: without either (the smoother alone) there is nothing to read back.
void AddComparison(const RunRequest& request, const EstimatorPipeline& session, const Streams& streams,
                   nlohmann::json* j, std::map<std::string, TrajectoryMetrics>* accuracy) {
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

// A reused --out folder: the outputs an earlier run wrote there for estimators this run did not run are
// removed once this run's are in place, so that the folder (and `gins eval` or `gins report` on it) shows
// this run alone. Only gins's own output names are touched.
void RemoveStaleOutputs(const std::string& dir, const Streams& streams) {
  for (api::Stream stream : {api::Stream::kEskf, api::Stream::kSmoother, api::Stream::kSmootherOnline,
                             api::Stream::kBatch, api::Stream::kEskfRts}) {
    const std::string name = api::StreamName(stream);
    if (streams.count(name) > 0) continue;
    for (const std::string& file :
         {dir + "/" + name + ".tum", dir + "/" + name + "_states.csv", dir + "/" + name + "_lla.csv"}) {
      std::error_code ec;
      std::filesystem::remove(file, ec);
    }
  }
}

}  // namespace

std::vector<std::string> SupportedModes() { return {"eskf", "smoother", "both", "batch", "all"}; }

void CheckInitTimeout(const std::string& name, double max_wait, const api::Session& session) {
  if (!session.init_timed_out()) return;
  throw RunError(name + ": not initialised after " + std::to_string(max_wait) + " s (init.max_wait_s): " +
                 api::internal::Access::session(session).Diagnosis());
}

void CheckReadCounts(const std::string& name, const ReadStats& rs, bool raw_gnss) {
  auto no_usable = [&](const std::string& what) {
    if (rs.lines == 0) return RunError(name + ": empty log (no lines)");
    std::string m = name + ": no usable " + what + " records (" + std::to_string(rs.lines) + " lines: " +
                    FormatRecordCounts(rs.records, ZeroCounts::kHideQuiet) + ", " +
                    std::to_string(rs.total_skipped()) + " damaged";
    if (!rs.examples.empty()) {
      m += "; first: line " + std::to_string(rs.examples.front().line) + ": " + rs.examples.front().reason + ": " +
           rs.examples.front().detail;
    }
    return RunError(m + ")");
  };
  if (CountOf<ImuSample>(rs.records) == 0) throw no_usable("IMU");
  if (CountOf<GnssRecord>(rs.records) == 0 && !raw_gnss) throw no_usable("GNSS");
}

void FinishSession(const std::string& name, api::Session* session) {
  try {
    session->Finish();
  } catch (const api::Error& e) {
    if (e.kind() == api::Error::Kind::kNoSolution) throw RunError(name + ": " + e.what());
    throw;
  }
}

RunResult Run(const api::Config& config, const RunRequest& request) {
  const auto wall_start = Clock::now();
  const Options& options = api::internal::Access::options(config);
  CheckMode(request.mode);
  api::SessionOptions session_options;
  api::ParseMode(request.mode, &session_options.mode);
  session_options.geodetic = false;  // the outputs are in ENU
  session_options.parallel = true;   // both and all: an estimator per core
  api::LogReader reader(request.log_path, config);
  std::error_code ec;
  std::filesystem::create_directories(request.out_dir, ec);
  if (ec) throw std::runtime_error(request.out_dir + ": cannot create output directory: " + ec.message());

  bool truth_checked = false;
  Streams streams;
  std::array<OutputStream*, 5> by_stream{};  // indexed by api::Stream: no look-up per state
  // Formatting and writing the outputs runs on a second thread, in the order the states come: at IMU rate
  // it costs about as much as the ESKF. Declared after `streams`, so it is joined before they close.
  using Item = std::pair<OutputStream*, api::State>;
  BatchPipe<Item> writer([&request](const Item& item) {
    const uint64_t written = item.first->count();
    item.first->Add(api::ToStateEstimate(item.second));
    if (request.on_output_state && item.first->count() > written) request.on_output_state(item.second);
  });
  // After what its callback uses: on an error the session (and its estimator threads) goes first.
  api::Session session(config, session_options);
  const EstimatorPipeline& internal = api::internal::Access::session(session);
  // States arrive only after initialisation, when the world frame (and so the truth in it) exists.
  session.OnState([&](const api::State& state) {
    OutputStream*& out = by_stream[static_cast<size_t>(state.stream)];
    if (out == nullptr) {
      if (request.truth_path && !truth_checked) {
        CheckTruth(*request.truth_path, *internal.frame());
        truth_checked = true;
      }
      const std::string name = api::StreamName(state.stream);
      auto& s = streams[name];
      s = std::make_unique<OutputStream>(name, request.out_dir, *internal.frame(),
                                         state.stream != api::Stream::kSmootherOnline);
      out = s.get();
    }
    writer.Push({out, state});
  });

  const ReadStats& read_stats = api::internal::Access::read_stats(reader);
  {
    // Reading and parsing run on a third thread, ahead of the estimators (a read error surfaces here, after
    // the records before it, as from a direct read). Gone before read_stats is read.
    ReadAhead<api::Record> records([&reader](api::Record* r) { return reader.Next(r); });
    api::Record rec;
    for (uint64_t n = 1; records.Next(&rec); ++n) {
      if (request.poll && n % 4096 == 0) request.poll();
      try {
        session.Push(rec);
      } catch (const api::Error& e) {
        // The IMU's units or axes (core/imu_checks.h): named with the log.
        if (e.kind() == api::Error::Kind::kInput) throw RunError(request.log_path + ": " + e.what());
        throw;
      }
      CheckInitTimeout(request.log_path, options.init.max_wait, session);
    }
  }
  CheckReadCounts(request.log_path, read_stats, !options.sensors.gnss.raw.obs_file.empty());
  FinishSession(request.log_path, &session);
  writer.Close();  // every state written (or the writer's error thrown) before the files are committed
  if (request.poll) request.poll();  // and after the two-sided passes Finish runs

  RunResult result;
  const CommitGroup commit;  // an interrupt from here on waits: all of the run's files, or none
  for (auto& [name, s] : streams) {
    for (auto& f : s->Commit(request.out_dir)) result.outputs.push_back(f);
  }
  RemoveStaleOutputs(request.out_dir, streams);
  result.summary = RunSummary(options, request, read_stats, session, streams, wall_start);
  AddComparison(request, internal, streams, &result.summary, &result.accuracy);

  AtomicFile summary(request.out_dir + "/summary.json");
  summary.Write(result.summary.dump(2) + "\n");
  summary.Commit();
  result.outputs.push_back(request.out_dir + "/summary.json");
  return result;
}

}  // namespace gins
