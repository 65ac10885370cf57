#include "apps/cli.h"

#include <glog/logging.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "apps/convert_command.h"
#include "apps/export_command.h"
#include "apps/interrupt.h"
#include "apps/eval_command.h"
#include "apps/report_command.h"
#include "apps/run_command.h"
#include "apps/stream_command.h"
#include "apps/api/access.h"
#include "config/config_loader.h"
#include "core/io/log_reader.h"
#include "core/sim/simulator.h"

namespace gins {
namespace {

// --- The comparison at the end of a run (summary.json's "comparison", solver/run_comparison.h) ----------------
std::string JsonNum(const nlohmann::json& v, const char* format) {
  if (!v.is_number()) return "-";
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, v.get<double>());
  return buf;
}

// Prints each output against the truth (one line each: the numbers of summary.json's "accuracy" and
// "comparison") and the smoother against the ESKF.
void PrintComparison(const nlohmann::json& s) {
  if (!s.contains("comparison")) return;
  const auto& c = s["comparison"];
  if (c.contains("error")) std::printf("  comparison failed: %s\n", c["error"].get<std::string>().c_str());
  const size_t n_outages = s.value("gnss_outages", nlohmann::json::array()).size() +
                           s.value("gnss_gaps", nlohmann::json::array()).size();
  const bool vs_truth = c.contains("vs_truth");
  if (vs_truth) {
    std::printf(
        "  vs truth          H RMSE m  H max m  V RMSE m  vel RMSE m/s  hdg RMSE deg  outage drift RMS/max m (%zu)%s\n",
        n_outages, n_outages ? "  H RMSE outside m" : "");
    for (const auto& [name, m] : c["vs_truth"].items()) {
      if (m.contains("error")) {
        std::printf("    %-15s %s\n", name.c_str(), m["error"].get<std::string>().c_str());
        continue;
      }
      const std::string drift_max = JsonNum(m["outage_drift_max_m"], "%.3f");
      std::printf("    %-15s %8s %8s %9s %13s %13s %11s / %s", name.c_str(),
                  JsonNum(m["rmse_horizontal_m"], "%.3f").c_str(), JsonNum(m["max_horizontal_m"], "%.3f").c_str(),
                  JsonNum(m["rmse_vertical_m"], "%.3f").c_str(), JsonNum(m["rmse_velocity_m_s"], "%.3f").c_str(),
                  JsonNum(m["rmse_heading_deg"], "%.3f").c_str(), JsonNum(m["outage_drift_rms_m"], "%.3f").c_str(),
                  drift_max.c_str());
      // The accuracy with GNSS (outside outages and their settle time), apart from the drift.
      if (m.contains("rmse_horizontal_outside_outages_m")) {
        std::printf("%*s %16s", static_cast<int>(9 - std::min<size_t>(9, drift_max.size())), "",
                    JsonNum(m["rmse_horizontal_outside_outages_m"], "%.4f").c_str());
      }
      std::printf("\n");
    }
    if (c.contains("best_horizontal")) {
      std::printf("  lowest horizontal RMSE: %s\n", c["best_horizontal"].get<std::string>().c_str());
    }
  }
  if (c.contains("smoother_vs_eskf") && !c["smoother_vs_eskf"].contains("error")) {
    const auto& d = c["smoother_vs_eskf"];
    std::printf("  smoother vs eskf: horizontal RMS difference %s m (max %s m at %s s), heading %s deg\n",
                JsonNum(d["rms_horizontal_difference_m"], "%.3f").c_str(),
                JsonNum(d["max_horizontal_difference_m"], "%.3f").c_str(),
                JsonNum(d["max_horizontal_difference_time_s"], "%.1f").c_str(),
                JsonNum(d["rms_heading_difference_deg"], "%.3f").c_str());
  }
}

// Each estimator's verdict (solver/health.h), one line each; a run that is not ok says so on stderr too.
void PrintHealth(const nlohmann::json& s) {
  if (!s.contains("health")) return;
  for (const auto& [name, h] : s["health"].items()) {
    std::string line = h["verdict"].get<std::string>();
    for (size_t i = 0; i < h["reasons"].size(); ++i) line += (i == 0 ? ": " : "; ") + h["reasons"][i].get<std::string>();
    std::printf("  health %-8s %s\n", name.c_str(), line.c_str());
    if (h["verdict"] != "ok") std::fprintf(stderr, "gins: warning: %s is %s\n", name.c_str(), line.c_str());
  }
}

// Whether every estimator's verdict is ok (for --strict).
bool AllHealthy(const nlohmann::json& s) {
  if (!s.contains("health")) return true;
  for (const auto& [name, h] : s["health"].items()) {
    if (h["verdict"] != "ok") return false;
  }
  return true;
}

void PrintRunReport(const RunRequest& req, const RunResult& r) {
  std::printf("gins: mode %s, log %s\n", req.mode.c_str(), req.log_path.c_str());
  const auto& s = r.summary;
  const auto& in = s["input"];
  std::printf("  records: %llu IMU, %llu ODOM, %llu GNSS; skipped lines: %zu kinds\n",
              static_cast<unsigned long long>(in["records"]["imu"].get<uint64_t>()),
              static_cast<unsigned long long>(in["records"]["odom"].get<uint64_t>()),
              static_cast<unsigned long long>(in["records"]["gnss"].get<uint64_t>()), in["skipped"].size());
  for (const auto& [reason, n] : in["skipped"].items()) {
    std::printf("    skipped %s: %llu\n", reason.c_str(), static_cast<unsigned long long>(n.get<uint64_t>()));
  }
  const auto& tm = s["timing"];
  std::printf("  wall %.2f s for %.1f s of log (real-time factor %.0fx)\n", tm["wall_s"].get<double>(),
              tm["log_duration_s"].get<double>(), tm["real_time_factor"].get<double>());
  for (const auto& f : r.outputs) std::printf("  wrote %s\n", f.c_str());
  PrintComparison(s);
  PrintHealth(s);
}

// --truth auto: NAME.truth.csv.gz or NAME.truth.csv beside the log NAME.txt[.gz] (or NAME[.gz]); "" if none.
std::string TruthBesideLog(const std::string& log) {
  std::string stem = log;
  for (const char* ext : {".gz", ".txt"}) {
    const size_t n = std::strlen(ext);
    if (stem.size() > n && stem.compare(stem.size() - n, n, ext) == 0) stem.resize(stem.size() - n);
  }
  for (const std::string& truth : {stem + ".truth.csv.gz", stem + ".truth.csv"}) {
    if (std::filesystem::is_regular_file(truth)) return truth;
  }
  return "";
}

}  // namespace

int RunCli(int argc, const char* const* argv, bool own_process) {
  if (!google::IsGoogleLoggingInitialized()) google::InitGoogleLogging("gins");
  FLAGS_logtostderr = true;
  FLAGS_minloglevel = google::GLOG_WARNING;

  CLI::App app{"gins: GNSS/INS fusion (error-state Kalman filter and sliding-window smoother)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("gins ") + api::Version());

  RunRequest req;
  std::string config_path;
  std::string truth_path;
  auto* run = app.add_subcommand("run", "Estimate a trajectory from a log");
  run->add_option("--config", config_path, "YAML config (see config/default.yaml)")->required()->check(CLI::ExistingFile);
  run->add_option("--log", req.log_path, "Sensor log (plain or .gz)")->required();
  run->add_option("--out", req.out_dir, "Output directory (created if missing)")->required();
  run->add_option("--mode", req.mode, "Estimator")->check(CLI::IsMember(SupportedModes()))->capture_default_str();
  run->add_option("--truth", truth_path,
                  "Truth CSV (docs/formats.md §4) for an accuracy summary; auto: the log's own, NAME.truth.csv[.gz] "
                  "beside NAME.txt[.gz], when there is one (docs/fleet.md)")
      ->check(CLI::ExistingFile | CLI::IsMember({"auto"}));
  std::string obs_path, nav_path;
  run->add_option("--obs", obs_path,
                  "RINEX 3 observation file for tightly coupled GNSS (raw_gnss.obs_file; the log's time in GPS s)")
      ->check(CLI::ExistingFile);
  run->add_option("--nav", nav_path, "RINEX 3 navigation file (raw_gnss.nav_file)")->check(CLI::ExistingFile);
  bool strict = false;
  run->add_flag("--strict", strict,
                "Exit 3 unless every estimator's health verdict is ok (degraded or failed: summary.json's health)");

  std::string sim_config, sim_out;
  auto* sim = app.add_subcommand("simulate", "Simulate a drive: writes log.txt and truth.csv");
  sim->add_option("--config", sim_config, "YAML config with a simulate: section")->required()->check(CLI::ExistingFile);
  sim->add_option("--out", sim_out, "Output directory (created if missing)")->required();

  EvalRequest eval_req;  // gins eval (apps/eval_command.h)
  auto* eval = AddEvalCommand(app, &eval_req);
  ConvertRequest convert_req;  // gins convert (apps/convert_command.h)
  auto* convert = AddConvertCommand(app, &convert_req);
  StreamRequest stream_req;  // gins stream (apps/stream_command.h)
  auto* stream = AddStreamCommand(app, &stream_req);
  ReportRequest report_req;  // gins report (apps/report_command.h)
  auto* report = AddReportCommand(app, &report_req);
  ExportRequest export_req;  // gins export (apps/export_command.h)
  auto* exp = AddExportCommand(app, &export_req);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Help and version print and succeed; every other parse error is a usage error (exit 2).
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }

  if (*stream) {
    if (stream_req.online && stream_req.mode != "smoother") {
      std::fprintf(stderr, "gins stream: --online needs --mode smoother\n");
      return 2;
    }
    return RunStream(stream_req, 0, stdout);
  }
  if (own_process) RemoveUnfinishedFilesOnInterrupt();
  if (*report) return RunReport(report_req);
  if (*eval) return RunEval(eval_req);
  if (*convert) return RunConvert(convert_req);
  if (*exp) return RunExport(export_req);
  try {
    if (*run) {
      api::Config config = api::Config::FromFile(config_path);
      if (!obs_path.empty() || !nav_path.empty()) {
        Options options = api::internal::Access::options(config);
        if (!obs_path.empty()) options.sensors.gnss.raw.obs_file = obs_path;
        if (!nav_path.empty()) options.sensors.gnss.raw.nav_file = nav_path;
        config = api::internal::Access::MakeConfig(options);
      }
      req.config_path = config_path;
      if (truth_path == "auto") truth_path = TruthBesideLog(req.log_path);
      if (!truth_path.empty()) req.truth_path = truth_path;
      const RunResult result = Run(config, req);
      PrintRunReport(req, result);
      if (strict && !AllHealthy(result.summary)) {
        std::fprintf(stderr, "gins: --strict: an estimator is not healthy (summary.json: health)\n");
        return 3;
      }
      return 0;
    }
    if (*sim) {
      const Options options = LoadOptions(sim_config);
      std::filesystem::create_directories(sim_out);
      const SimulationResult r = Simulate(options.simulate, sim_out);
      std::printf("gins simulate: %.1f s, %llu IMU, %llu GNSS, %llu GVEL, %llu ODOM records -> %s/log.txt, "
                  "%s/truth.csv\n",
                  r.duration, static_cast<unsigned long long>(CountOf<ImuSample>(r.records)),
                  static_cast<unsigned long long>(CountOf<GnssRecord>(r.records)),
                  static_cast<unsigned long long>(CountOf<GnssVelocityRecord>(r.records)),
                  static_cast<unsigned long long>(CountOf<WheelRecord>(r.records)), sim_out.c_str(), sim_out.c_str());
      return 0;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gins: error: %s\n", e.what());
    return 1;
  }
  return 2;
}

}  // namespace gins
