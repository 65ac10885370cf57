#include "apps/report_command.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace gins {
namespace {

namespace fs = std::filesystem;

// A run to report: its summary file, or none (a run directory without one: the run failed or is running).
struct RunEntry {
  std::string run;      // the run directory as given or found
  std::string summary;  // empty: missing
};

// Each input: a summary file; a run directory (it holds summary.json); or a folder of runs, searched below
// for summary.json files (in path order). A directory with none of them is a run without a summary.
std::vector<RunEntry> FindRuns(const std::vector<std::string>& inputs) {
  std::vector<RunEntry> runs;
  for (std::string input : inputs) {
    while (input.size() > 1 && input.back() == '/') input.pop_back();  // "out/fleet/*/" names dirs
    const fs::path p(input);
    if (fs::is_regular_file(p)) {
      runs.push_back({p.parent_path().string(), input});
      continue;
    }
    if (!fs::is_directory(p)) throw std::runtime_error(input + ": no such file or directory");
    if (fs::is_regular_file(p / "summary.json")) {
      runs.push_back({input, (p / "summary.json").string()});
      continue;
    }
    // A folder of runs: every directory below it that holds a summary.json is a run; every other directory
    // with nothing below it is a run that failed (or is running): listed, as `DIR/*/` would list it.
    std::vector<RunEntry> found;
    std::vector<fs::path> leaves;
    for (const auto& e : fs::recursive_directory_iterator(p)) {
      if (e.is_regular_file() && e.path().filename() == "summary.json") {
        found.push_back({e.path().parent_path().string(), e.path().string()});
      } else if (e.is_directory() && fs::is_empty(e.path())) {
        leaves.push_back(e.path());
      }
    }
    for (const fs::path& leaf : leaves) {
      bool in_run = false;  // a run's own empty subfolder is not a run
      for (const RunEntry& r : found) {
        const std::string dir = r.run + "/";
        in_run = in_run || leaf.string().compare(0, dir.size(), dir) == 0;
      }
      if (!in_run) found.push_back({leaf.string(), ""});
    }
    std::sort(found.begin(), found.end(), [](const RunEntry& a, const RunEntry& b) { return a.run < b.run; });
    if (found.empty()) runs.push_back({input, ""});
    for (const RunEntry& r : found) runs.push_back(r);
  }
  return runs;
}

nlohmann::json ReadSummary(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(path + ": not a summary (" + std::string(e.what()) + ")");
  }
}

double Number(const nlohmann::json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_number() ? j[key].get<double>() : 0.0;
}

std::string Fixed(const nlohmann::json& v, const char* format) {
  if (!v.is_number()) return "-";
  char buf[32];
  std::snprintf(buf, sizeof(buf), format, v.get<double>());
  return buf;
}

uint64_t Count(const nlohmann::json& row, const char* key) { return row.value(key, uint64_t{0}); }

// A path in a column of `width`: its end, which tells runs apart (a fleet's runs share their start).
std::string Tail(const std::string& s, size_t width) {
  return s.size() <= width ? s : "..." + s.substr(s.size() - (width - 3));
}

// A path as the table shows it: relative to the current folder when it lies below it (summaries store
// absolute paths).
std::string Shown(const std::string& path) {
  std::error_code ec;
  const fs::path cwd = fs::current_path(ec);
  if (ec || path.empty() || path.front() != '/') return path;
  const fs::path rel = fs::path(path).lexically_relative(cwd);
  return rel.empty() || *rel.begin() == ".." ? path : rel.string();
}

void PrintTable(const nlohmann::json& rows) {
  std::printf("%-24s %-24s %9s %-8s %11s %11s %11s %11s %11s %8s %8s %8s %7s\n", "run", "log", "log s", "mode",
              "eskf H m", "smooth H m", "online H m", "batch H m", "rts H m", "rejected", "skipped", "watchdog", "RTF");
  for (const auto& r : rows) {
    if (r.contains("error")) {
      std::printf("%-24s %s\n", Tail(r["run"].get<std::string>(), 24).c_str(), r["error"].get<std::string>().c_str());
      continue;
    }
    const auto& h = r["rmse_horizontal_m"];
    std::printf("%-24s %-24s %9s %-8s %11s %11s %11s %11s %11s %8llu %8llu %8llu %7s\n",
                Tail(r["run"].get<std::string>(), 24).c_str(), Tail(Shown(r["log"].get<std::string>()), 24).c_str(),
                Fixed(r["duration_s"], "%.1f").c_str(), r["mode"].get<std::string>().c_str(),
                Fixed(h.value("eskf", nlohmann::json()), "%.3f").c_str(),
                Fixed(h.value("smoother", nlohmann::json()), "%.3f").c_str(),
                Fixed(h.value("smoother_online", nlohmann::json()), "%.3f").c_str(),
                Fixed(h.value("batch", nlohmann::json()), "%.3f").c_str(),
                Fixed(h.value("eskf_rts", nlohmann::json()), "%.3f").c_str(),
                static_cast<unsigned long long>(Count(r, "rejected")),
                static_cast<unsigned long long>(Count(r, "skipped_lines")),
                static_cast<unsigned long long>(Count(r, "watchdog_resets")),
                (Fixed(r["real_time_factor"], "%.0f") + "x").c_str());
  }
}

}  // namespace

nlohmann::json ReportRow(const std::string& run, const nlohmann::json& s) {
  nlohmann::json row;
  row["run"] = run;
  const std::string log = s.value("log", std::string());
  row["log"] = log;
  row["mode"] = s.value("mode", std::string("?"));
  const nlohmann::json timing = s.value("timing", nlohmann::json::object());
  row["duration_s"] = Number(timing, "log_duration_s");
  row["wall_s"] = Number(timing, "wall_s");
  row["real_time_factor"] = Number(timing, "real_time_factor");
  row["rmse_horizontal_m"] = nlohmann::json::object();
  row["rmse_3d_m"] = nlohmann::json::object();
  // (value() returns a copy: kept in a variable, not iterated as a temporary.)
  const nlohmann::json accuracy = s.value("accuracy", nlohmann::json::object());
  for (const auto& [stream, a] : accuracy.items()) {
    row["rmse_horizontal_m"][stream] = a.value("rmse_horizontal_m", nlohmann::json());
    row["rmse_3d_m"][stream] = a.value("rmse_3d_m", nlohmann::json());
  }
  // Rejections: each estimator's, by measurement and reason, and the session's refusals.
  uint64_t rejected = 0, resets = 0;
  nlohmann::json by = nlohmann::json::object();
  const nlohmann::json estimators = s.value("estimators", nlohmann::json::object());
  for (const auto& [name, est] : estimators.items()) {
    for (const auto& [measurement, counts] : est.items()) {
      if (!counts.is_object() || !counts.contains("rejected") || !counts["rejected"].is_object()) continue;
      for (const auto& [reason, n] : counts["rejected"].items()) {
        by[name + "." + measurement + "." + reason] = n;
        rejected += n.get<uint64_t>();
      }
    }
    if (est.contains("watchdog")) resets += est["watchdog"].value("count", uint64_t{0});
  }
  const nlohmann::json input = s.value("input", nlohmann::json::object());
  const nlohmann::json refused = input.value("refused", nlohmann::json::object());
  for (const auto& [measurement, reasons] : refused.items()) {
    for (const auto& [reason, n] : reasons.items()) {
      by["input." + measurement + "." + reason] = n;
      rejected += n.get<uint64_t>();
    }
  }
  uint64_t skipped = 0;
  const nlohmann::json skipped_by = input.value("skipped", nlohmann::json::object());
  for (const auto& [reason, n] : skipped_by.items()) skipped += n.get<uint64_t>();
  row["rejected"] = rejected;
  row["rejected_by"] = by;
  row["skipped_lines"] = skipped;
  row["watchdog_resets"] = resets;
  return row;
}

CLI::App* AddReportCommand(CLI::App& app, ReportRequest* req) {
  auto* report = app.add_subcommand("report", "Tabulate many runs: one row per run's summary.json");
  report->footer(
      "Each input is a run directory (holding summary.json), a summary.json, or a folder searched for run\n"
      "directories. Columns: the log and its duration, the mode, the horizontal RMSE of each output against\n"
      "the truth (runs with --truth), measurements rejected (estimators' gates and checks, and the session's\n"
      "refusals), damaged log lines skipped, watchdog resets, real-time factor. A run directory without a\n"
      "summary (the run failed) is listed as such and makes the exit code 1.");
  report->add_option("inputs", req->inputs, "Run directories, summary.json files or folders of runs")->required();
  report->add_option("--json", req->json_path, "Also write the rows (and totals) to this JSON file");
  return report;
}

int RunReport(const ReportRequest& req) {
  try {
    nlohmann::json rows = nlohmann::json::array();
    nlohmann::json totals = {{"runs", 0},     {"missing", 0},       {"duration_s", 0.0},
                             {"rejected", 0}, {"skipped_lines", 0}, {"watchdog_resets", 0}};
    for (const RunEntry& e : FindRuns(req.inputs)) {
      if (e.summary.empty()) {
        rows.push_back({{"run", e.run}, {"error", "no summary.json (the run failed or has not finished)"}});
        totals["missing"] = totals["missing"].get<int>() + 1;
        continue;
      }
      const nlohmann::json row = ReportRow(e.run, ReadSummary(e.summary));
      totals["runs"] = totals["runs"].get<int>() + 1;
      totals["duration_s"] = totals["duration_s"].get<double>() + row["duration_s"].get<double>();
      for (const char* k : {"rejected", "skipped_lines", "watchdog_resets"}) {
        totals[k] = totals[k].get<uint64_t>() + row[k].get<uint64_t>();
      }
      rows.push_back(row);
    }
    PrintTable(rows);
    std::printf("%d runs, %.2f h of log; %llu rejected, %llu skipped lines, %llu watchdog resets",
                totals["runs"].get<int>(), totals["duration_s"].get<double>() / 3600.0,
                static_cast<unsigned long long>(totals["rejected"].get<uint64_t>()),
                static_cast<unsigned long long>(totals["skipped_lines"].get<uint64_t>()),
                static_cast<unsigned long long>(totals["watchdog_resets"].get<uint64_t>()));
    if (totals["missing"].get<int>() > 0) std::printf("; %d without a summary", totals["missing"].get<int>());
    std::printf("\n");
    if (!req.json_path.empty()) {
      std::ofstream out(req.json_path);
      out << nlohmann::json{{"runs", rows}, {"totals", totals}}.dump(2) << "\n";
      if (!out) throw std::runtime_error(req.json_path + ": write failed");
    }
    return totals["missing"].get<int>() > 0 ? 1 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gins: error: %s\n", e.what());
    return 1;
  }
}

}  // namespace gins
