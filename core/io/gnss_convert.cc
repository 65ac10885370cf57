#include "core/io/gnss_convert.h"

#include <cmath>
#include <vector>

#include "core/io/log_writer.h"

namespace gins {
namespace {

// A gins log's IMU and ODOM records; its GNSS and GVEL records are counted and dropped (the converted
// GNSS file replaces them: two receivers' fixes in one log would fight).
class LogSource : public RecordSource {
 public:
  LogSource(const std::string& path, const InputOptions& options, ConvertedInput* input)
      : RecordSource(path), reader_(path, options), input_(input) {
    stats_.description = "gins log";
  }
  bool Next(LogRecord* r) override {
    while (reader_.Next(r)) {
      if (r->is<GnssRecord>() || r->is<GnssVelocityRecord>()) {
        ++(r->is<GnssRecord>() ? input_->dropped_gnss : input_->dropped_gvel);
        continue;
      }
      if (!file_.has_range) file_.t_first = r->t();
      file_.has_range = true;
      file_.t_last = r->t();
      ++file_.written;
      ++stats_.records[r->type_index()];
      return true;
    }
    return false;
  }
  // The reader's counts as a converted file's.
  ConvertedFile Result() const {
    ConvertedFile f = file_;
    const ReadStats& s = reader_.stats();
    f.lines = s.lines;
    f.skipped = s.skipped;
    f.issues = s.examples;
    return f;
  }

 private:
  LogReader reader_;
  ConvertedInput* input_;
};

std::unique_ptr<RecordSource> OpenGnss(const GnssConvertInputs& in, const InputOptions& options) {
  if (in.format == "rtklib-pos") return OpenRtklibPos(in.gnss_path, options, in.options);
  if (in.format == "nmea") return OpenNmea(in.gnss_path, options, in.options);
  if (in.format == "csv") {
    if (in.gnss_columns.empty()) throw InputError("--format csv needs --gnss-columns (the GNSS file's column map)");
    return OpenCsv(in.gnss_path, ParseColumnMap(in.gnss_columns, CsvKind::kGnss, "--gnss-columns"), options);
  }
  throw InputError("unknown GNSS format '" + in.format + "' (rtklib-pos, nmea, csv)");
}

// How the GNSS file's times reached the log's clock.
std::string LeapText(const GnssFileStats& s, LogTimeScale scale) {
  if (s.time_system.empty() || s.leap_seconds.empty()) return "times as in the file";
  std::string counts;
  for (const auto& [leap, n] : s.leap_seconds) {
    counts += FormatText("%s%d s", counts.empty() ? "" : ", ", leap);
  }
  if (s.time_system == "UTC" && scale == LogTimeScale::kGps) return "UTC + leap seconds " + counts + " = GPS time";
  if (s.time_system == "GPST" && scale == LogTimeScale::kUnixUtc)
    return "GPST - leap seconds " + counts + " = Unix UTC";
  return s.time_system + ", no leap seconds (the log's scale)";
}

std::string Header(const GnssConvertInputs& in, const RecordSource& gnss, const ConvertedInput& imu, bool wheel) {
  std::string h = "gins convert --format " + in.format + ": GNSS " + in.gnss_path + " (" + gnss.stats().description +
                  "; " + LeapText(gnss.stats(), in.options.time_scale) + ", " +
                  (in.options.time_scale == LogTimeScale::kGps ? "GPS seconds since 1980-01-06" : "Unix UTC") +
                  "), IMU from " + in.imu_path + " (" + imu.kind;
  if (imu.kind == "gins log") h += "; its own GNSS and GVEL records not copied";
  h += ")";
  if (wheel) h += ", wheels from " + in.wheel_path + " (csv)";
  return h;
}

// Both sides must share a time base: ranges that do not overlap mean one is, e.g., Unix time and the other
// GPS time, and the log would hold two separate halves.
void CheckTimeBases(const ConvertedInput& imu, const ConvertedInput& gnss) {
  const ConvertedFile& i = imu.file;
  const ConvertedFile& g = gnss.file;
  if (i.t_last >= g.t_first && g.t_last >= i.t_first) return;
  const double apart = g.t_first - i.t_first;
  std::string hint = "different time bases?";
  if (std::abs(std::abs(apart) - kGpsEpochUnix) < 86400.0) {
    hint = "one is Unix time, the other GPS time: --time-scale " + std::string(apart < 0 ? "unix" : "gps") + "?";
  } else if (i.t_last < kMinAbsoluteTime || g.t_last < kMinAbsoluteTime) {
    hint = "one clock is not absolute (seconds of week, or since power-on): the GNSS file's times are absolute";
  } else if (std::abs(apart) < 86400.0) {
    hint = "not the same recording?";
  }
  throw InputError(i.path +
                   FormatText(": IMU times [%.3f, %.3f] s and the GNSS times [%.3f, %.3f] s of ", i.t_first, i.t_last,
                              g.t_first, g.t_last) +
                   g.path + " do not overlap: " + hint);
}

std::string Count(uint64_t n) { return std::to_string(n); }

void AppendInput(const ConvertedInput& in, LogTimeScale scale, std::string* out) {
  const ConvertedFile& f = in.file;
  const GnssFileStats& s = in.stats;
  const std::string types = FormatRecordCounts(s.records, ZeroCounts::kHide);
  *out += FormatText("  %-5s ", in.role.c_str()) + in.kind + " " + f.path + ": " + Count(f.lines) + " lines, " +
          Count(f.written) + " records" + (types.empty() ? "" : " (" + types + ")");
  if (f.has_range) *out += FormatText(", t %.3f .. %.3f s", f.t_first, f.t_last);
  *out += "\n";
  if (in.role == "GNSS") *out += "    time: " + LeapText(s, scale) + "\n";
  for (const auto& [q, n] : s.qualities) *out += "    quality " + q + ": " + Count(n) + "\n";
  if (in.dropped_gnss + in.dropped_gvel > 0) {
    *out += "    dropped its own " + Count(in.dropped_gnss) + " GNSS and " + Count(in.dropped_gvel) +
            " GVEL records (the GNSS file replaces them)\n";
  }
  for (const auto& [what, n] : s.dropped) *out += "    dropped " + what + ": " + Count(n) + "\n";
  for (const auto& [what, n] : s.ignored) *out += "    ignored " + what + ": " + Count(n) + "\n";
  *out += FormatIssueCounts("skipped", f.skipped, f.issues);
  *out += FormatIssueCounts("warning", f.warnings, f.issues);
}

}  // namespace

GnssConversion ConvertGnss(const GnssConvertInputs& in, const InputOptions& options, const std::string& out_path) {
  GnssConversion c;
  c.out_path = out_path;
  c.gnss = {"GNSS", in.format, {}, {}, 0, 0};
  c.imu = {"IMU", in.imu_columns.empty() ? "gins log" : "csv", {}, {}, 0, 0};
  c.wheel = {"wheel", "csv", {}, {}, 0, 0};
  c.has_wheel = !in.wheel_path.empty();
  c.time_scale = in.options.time_scale;
  if (c.has_wheel && in.wheel_columns.empty()) throw InputError("--wheel needs --wheel-columns (its column map)");
  // The maps first: a mistake in one is found before any file is read.
  std::unique_ptr<RecordSource> imu =
      in.imu_columns.empty()
          ? std::unique_ptr<RecordSource>(std::make_unique<LogSource>(in.imu_path, options, &c.imu))
          : OpenCsv(in.imu_path, ParseColumnMap(in.imu_columns, CsvKind::kImu, "--imu-columns"), options);
  std::unique_ptr<RecordSource> wheel =
      c.has_wheel
          ? OpenCsv(in.wheel_path, ParseColumnMap(in.wheel_columns, CsvKind::kWheel, "--wheel-columns"), options)
          : nullptr;
  std::unique_ptr<RecordSource> gnss = OpenGnss(in, options);
  std::vector<RecordSource*> sources = {imu.get()};  // the merge's tie order: IMU, wheels, GNSS
  if (wheel) sources.push_back(wheel.get());
  sources.push_back(gnss.get());
  std::vector<LogRecord> head(sources.size());
  std::vector<char> live(sources.size());
  for (size_t i = 0; i < sources.size(); ++i) live[i] = sources[i]->Next(&head[i]);
  LogWriter out(out_path);
  c.header = Header(in, *gnss, c.imu, c.has_wheel);
  out.Comment(c.header);
  uint64_t total = 0;
  for (;;) {
    int next = -1;
    for (size_t i = 0; i < sources.size(); ++i) {
      if (live[i] && (next < 0 || head[i].t() < head[next].t())) next = static_cast<int>(i);
    }
    if (next < 0) break;
    const LogRecord& r = head[next];
    out.Add(r);
    if (total++ == 0) c.t_first = r.t();
    c.t_last = std::max(c.t_last, r.t());
    ++c.written[r.type_index()];
    live[next] = sources[next]->Next(&head[next]);
  }
  c.gnss.file = gnss->file();
  c.gnss.stats = gnss->stats();
  c.imu.file = in.imu_columns.empty() ? static_cast<LogSource*>(imu.get())->Result() : imu->file();
  c.imu.stats = imu->stats();
  if (wheel) {
    c.wheel.file = wheel->file();
    c.wheel.stats = wheel->stats();
  }
  if (CountOf<GnssRecord>(c.written) == 0) {
    uint64_t dropped = 0;
    for (const auto& [what, n] : c.gnss.stats.dropped) dropped += n;
    throw InputError(in.gnss_path + ": no usable fixes in " + Count(c.gnss.file.lines) + " lines (" +
                     Count(c.gnss.file.total_skipped()) + " damaged, " + Count(dropped) + " dropped by quality)");
  }
  if (CountOf<ImuSample>(c.written) == 0) {
    throw InputError(in.imu_path + ": no IMU records in " + Count(c.imu.file.lines) + " lines");
  }
  CheckTimeBases(c.imu, c.gnss);
  out.Commit();
  return c;
}

std::string FormatGnssConversionSummary(const GnssConversion& c) {
  std::string out = "gins convert: " + c.gnss.kind + " -> " + c.out_path + " (" +
                    FormatRecordCounts(c.written, ZeroCounts::kShow) + " records; t " +
                    FormatText("%.3f .. %.3f s", c.t_first, c.t_last) + ")\n";
  AppendInput(c.gnss, c.time_scale, &out);
  AppendInput(c.imu, c.time_scale, &out);
  if (c.has_wheel) AppendInput(c.wheel, c.time_scale, &out);
  return out;
}

}  // namespace gins
