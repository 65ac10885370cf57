#include "apps/export_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/io/geo_export.h"
#include "core/io/geo_formats.h"
#include "core/io/log_reader.h"
#include "core/io/trajectory_writer.h"

namespace gins {
namespace fs = std::filesystem;
namespace {

// The streams of a run folder, the smoother's first: the default export.
constexpr const char* kStreams[] = {"smoother", "batch", "eskf_rts", "eskf", "smoother_online"};

// The output file of `stream` in a run folder: its states CSV (with σ and velocity) or its TUM file.
std::string StreamFile(const std::string& dir, const std::string& stream) {
  for (const std::string& f : {dir + "/" + stream + "_states.csv", dir + "/" + stream + ".tum"}) {
    if (fs::exists(f)) return f;
  }
  return "";
}

std::optional<GeodeticPoint> ParseOrigin(const std::string& text) {
  if (text.empty()) return std::nullopt;
  GeodeticPoint g;
  char c1 = 0, c2 = 0;
  std::istringstream in(text);
  in.imbue(std::locale::classic());
  if (!(in >> g.lat_deg >> c1 >> g.lon_deg >> c2 >> g.alt_m) || c1 != ',' || c2 != ',' ||
      !IsPlausibleGeodetic(g.lat_deg, g.lon_deg, g.alt_m)) {
    throw InputError("--origin '" + text + "': expected LAT,LON,HEIGHT (deg, deg, m)");
  }
  return g;
}

nlohmann::json ReadSummary(const std::string& path) {
  std::ifstream in(path);
  nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) throw InputError(path + ": not a gins summary (JSON object)");
  return j;
}

// The outages and gaps of the run, and the fixes the stream's estimator rejected (eskf and eskf_rts: the
// ESKF's; smoother, smoother_online and batch: the smoother's; both for another name), placed where the log's
// GNSS record of that time put the antenna.
void AddRunMarkers(const nlohmann::json& summary, const std::string& stream, GeoTrack* track) {
  for (const char* key : {"gnss_outages", "gnss_gaps"}) {
    if (!summary.contains(key)) continue;
    for (const auto& w : summary[key]) {
      track->no_fix.push_back({w.at(0).get<double>(), w.at(1).get<double>(), key[5] == 'o' ? "outage" : "gap"});
    }
  }
  std::sort(track->no_fix.begin(), track->no_fix.end(),
            [](const GeoInterval& a, const GeoInterval& b) { return a.t0 < b.t0; });
  std::vector<std::pair<double, std::string>> rejected;
  const std::string estimator = stream.rfind("eskf", 0) == 0                                     ? "eskf"
                                : stream.rfind("smoother", 0) == 0 || stream == "batch" ? "smoother"
                                                                                        : "";
  const nlohmann::json estimators = summary.value("estimators", nlohmann::json::object());
  for (const auto& [name, est] : estimators.items()) {
    if (!est.contains("gnss_position") || (!estimator.empty() && name != estimator)) continue;
    const nlohmann::json times = est["gnss_position"].value("rejected_times", nlohmann::json::array());
    for (const auto& t : times) {
      rejected.emplace_back(t.get<double>(), name);
    }
  }
  if (rejected.empty() || !summary.contains("log")) return;
  std::sort(rejected.begin(), rejected.end());
  // The log's fixes, nearest in time to each rejected one (its time may carry the estimated offset).
  std::vector<GnssRecord> fixes;
  try {
    LogReader reader(summary["log"].get<std::string>(), InputOptions{});
    LogRecord r;
    while (reader.Next(&r)) {
      if (const GnssRecord* fix = r.get_if<GnssRecord>()) fixes.push_back(*fix);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gins export: the rejected fixes are not marked: %s\n", e.what());
    return;
  }
  for (const auto& [t, name] : rejected) {
    const auto it = std::lower_bound(fixes.begin(), fixes.end(), t,
                                     [](const GnssRecord& g, double x) { return g.t < x; });
    const GnssRecord* best = nullptr;
    for (auto c : {it, it == fixes.begin() ? it : std::prev(it)}) {
      if (c != fixes.end() && (best == nullptr || std::abs(c->t - t) < std::abs(best->t - t))) best = &*c;
    }
    if (best != nullptr && std::abs(best->t - t) < 0.5) {
      track->rejected.push_back({t, best->lat_deg, best->lon_deg, best->alt_m, name});
    }
  }
}

}  // namespace

CLI::App* AddExportCommand(CLI::App& app, ExportRequest* req) {
  auto* exp = app.add_subcommand("export", "Write a run's output, a trajectory or a truth in another format");
  exp->footer(
      "INPUT is a run folder (its --stream output, the smoother's by default) or a file: our .tum,\n"
      "_states.csv or _lla.csv, a truth CSV, or a foreign TUM file with --origin. From a run folder (or a\n"
      "file in one) the map formats mark the GNSS outages and gaps and the fixes the estimators rejected.\n"
      "  kml, gpx, geojson  the track for Google Earth, QGIS, GDAL (WGS84, ellipsoidal height)\n"
      "  nmea               GGA + RMC (+ GST with the σ, HDT with the heading) at --rate\n"
      "  lla                t, latitude, longitude, height (and σ) as CSV\n"
      "  tum                t x y z qx qy qz qw in the ENU frame of --frame (a run), e.g. a truth for evo\n"
      "Times for NMEA and GPX: --time-scale gps (seconds since 1980-01-06, GPS time) or unix (UTC).\n"
      "Formats: docs/formats.md §5.7.");
  exp->add_option("--format", req->format, "Output format")
      ->required()
      ->check(CLI::IsMember({"kml", "gpx", "geojson", "nmea", "lla", "tum"}));
  exp->add_option("input", req->input, "Run folder or trajectory file")->required()->check(CLI::ExistingPath);
  exp->add_option("--out", req->out_path, "File to write")->required();
  exp->add_option("--stream", req->stream, "With a run folder: the output to export")
      ->check(CLI::IsMember({"eskf", "smoother", "smoother_online", "batch", "eskf_rts"}));
  exp->add_option("--origin", req->origin, "LAT,LON,HEIGHT of a foreign TUM file's frame");
  exp->add_option("--frame", req->frame, "tum: write in the frame of this run folder or output file")
      ->check(CLI::ExistingPath);
  exp->add_option("--time-scale", req->time_scale, "What the log's times count (docs/formats.md §2.6)")
      ->check(CLI::IsMember({"gps", "unix"}))
      ->capture_default_str();
  exp->add_option("--rate", req->rate_hz, "nmea: epochs per second (0: every state)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  return exp;
}

int RunExport(const ExportRequest& req) {
  try {
    std::string file = req.input, summary_path;
    if (fs::is_directory(req.input)) {
      std::vector<std::string> names;
      if (!req.stream.empty()) names.push_back(req.stream);
      for (const char* s : kStreams) names.push_back(s);
      file.clear();
      for (const std::string& n : names) {
        if (!(file = StreamFile(req.input, n)).empty() || !req.stream.empty()) break;
      }
      if (file.empty()) {
        throw InputError(req.input + ": no " + (req.stream.empty() ? "gins output" : req.stream + " output") +
                         " (.tum, _states.csv) in this folder");
      }
    } else if (!req.stream.empty()) {
      throw InputError("--stream selects an output of a run folder; " + req.input + " is a file");
    }
    const fs::path beside = fs::path(file).parent_path() / "summary.json";
    if (fs::exists(beside)) summary_path = beside.string();

    const ExportSource source = ReadExportSource(file, ParseOrigin(req.origin));
    std::string name = source.trajectory.mode.empty() ? fs::path(file).stem().string() : source.trajectory.mode;
    GeoTrack track = ToGeoTrack(source, name);
    if (!summary_path.empty() && source.kind != "truth") AddRunMarkers(ReadSummary(summary_path), name, &track);

    LogTimeScale scale = LogTimeScale::kGps;
    ParseLogTimeScale(req.time_scale, &scale);
    AtomicFile out(req.out_path);
    if (req.format == "kml" || req.format == "gpx" || req.format == "geojson") {
      GeoWriteOptions options;
      options.time_scale = scale;
      if (req.format == "kml") WriteKml(track, options, out.stream());
      if (req.format == "gpx") WriteGpx(track, options, out.stream());
      if (req.format == "geojson") WriteGeoJson(track, options, out.stream());
    } else if (req.format == "nmea") {
      NmeaExportOptions options;
      options.rate_hz = req.rate_hz;
      options.time_scale = scale;
      WriteNmea(track, options, out.stream());
    } else if (req.format == "lla") {
      WriteGeodeticCsv(track, out.stream());
    } else {
      GeodeticPoint origin = *source.trajectory.origin;
      if (!req.frame.empty()) {
        const std::string frame_file = fs::is_directory(req.frame) ? req.frame + "/summary.json" : req.frame;
        if (fs::path(frame_file).filename() == "summary.json") {
          const nlohmann::json s = ReadSummary(frame_file);
          const auto& o = s.at("origin_lla");
          origin = {o.at(0).get<double>(), o.at(1).get<double>(), o.at(2).get<double>()};
        } else {
          const Trajectory t = ReadTrajectory(frame_file);
          if (!t.origin) throw InputError(frame_file + ": no origin to take the frame from");
          origin = *t.origin;
        }
      }
      WriteTumInFrame(source, origin, out.stream());
    }
    out.Commit();
    const GeoFeatureCounts counts = CountGeoFeatures(track);
    std::printf("gins export: %s (%s, %zu states) -> %s (%s; %d lines, %d points marked)\n", file.c_str(),
                source.kind.c_str(), track.samples.size(), req.out_path.c_str(), req.format.c_str(), counts.lines,
                counts.points);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gins: error: %s\n", e.what());
    return 1;
  }
}

}  // namespace gins
