#include "apps/stream_command.h"

#include <pthread.h>
#include <signal.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <optional>
#include <stdexcept>
#include <string>

#include "apps/api/access.h"
#include "apps/api/convert.h"
#include "apps/run_command.h"
#include "core/io/geo_export.h"
#include "core/io/trajectory_writer.h"
#include "gins/gins.h"

namespace gins {
namespace {

constexpr char kInputName[] = "<stdin>";

// SIGINT and SIGTERM while streaming are blocked (in this thread and in every thread started later, e.g.
// Ceres's) and read from a signalfd that the reader polls beside the input: the input then ends after its
// last complete line, and everything read is estimated and written before the exit. Without a signalfd the
// signals keep their default action.
class StopSignals {
 public:
  StopSignals() {
    sigemptyset(&mask_);
    sigaddset(&mask_, SIGINT);
    sigaddset(&mask_, SIGTERM);
    if (pthread_sigmask(SIG_BLOCK, &mask_, &old_) != 0) return;
    fd_ = signalfd(-1, &mask_, SFD_CLOEXEC | SFD_NONBLOCK);
    if (fd_ < 0) pthread_sigmask(SIG_SETMASK, &old_, nullptr);
  }
  ~StopSignals() {
    if (fd_ < 0) return;
    Received();  // consumed, so that unblocking does not deliver it again
    ::close(fd_);
    pthread_sigmask(SIG_SETMASK, &old_, nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  int fd() const { return fd_; }
  // The signal that stopped the input, 0 if none.
  int Received() {
    signalfd_siginfo info;
    if (fd_ >= 0 && ::read(fd_, &info, sizeof(info)) == static_cast<ssize_t>(sizeof(info))) {
      received_ = static_cast<int>(info.ssi_signo);
    }
    return received_;
  }

 private:
  sigset_t mask_, old_;
  int fd_ = -1;
  int received_ = 0;
};

// One stream's states as the lines of `gins run`'s file for it (the same filter and formatting), each
// flushed as it is written.
class StateLines {
 public:
  StateLines(std::FILE* out, api::Stream stream, const std::string& format, const NmeaExportOptions& nmea)
      : out_(out), stream_(stream), format_(format), nmea_(nmea) {}

  void Add(const api::State& state, const api::Session& session) {
    if (state.stream != stream_) return;
    const StateEstimate e = api::ToStateEstimate(state);
    if (!filter_.Accept(e)) return;
    const LocalEnuFrame& frame = *api::internal::Access::session(session).frame();
    if (written_ == 0) {
      // The CSVs start with their column names; the states CSV's origin goes to stderr (the TUM file's
      // comment line carries it).
      if (format_ == "tum") std::fputs(TrajectoryHeader(api::StreamName(stream_), frame.origin()).c_str(), out_);
      if (format_ == "csv") {
        std::fprintf(stderr, "gins stream: %s states in ENU, origin_lla=%.10f %.10f %.4f\n", api::StreamName(stream_),
                     frame.origin().lat_deg, frame.origin().lon_deg, frame.origin().alt_m);
        std::fputs(kStatesCsvColumns, out_);
      }
      if (format_ == "lla") std::fputs(kGeodeticCsvColumns, out_);
    }
    if (format_ == "csv") {
      WriteStatesCsvLine(out_, e.x, e.sigma_p, e.sigma_v, e.sigma_att, e.odom_scale);
    } else if (format_ == "lla") {
      if (!geodetic_) geodetic_.emplace(frame);
      WriteGeodeticCsvLine(out_, &*geodetic_, e.x, e.sigma_p);
    } else if (format_ == "nmea") {
      if (!OnNmeaGrid(e.x.t, nmea_.rate_hz, &next_nmea_t_)) return;
      if (!HasDate(e.x.t)) {
        throw std::runtime_error("state at t=" + std::to_string(e.x.t) +
                                 " s: not an absolute time, NMEA needs the UTC date and time (docs/formats.md §2.6)");
      }
      TrajectorySample s;
      s.t = e.x.t;
      s.p_w = e.x.p_wb;
      s.q_wb = e.x.q_wb;
      s.v_w = e.x.v_w;
      s.sigma_p = e.sigma_p;
      s.yaw_known = e.sigma_att.z() < kUnknownYawSigmaBound;
      const GeoSample g = ToGeoSample(frame, s, SampleContent{true, true, true});
      WriteNmeaEpoch(g, QualityOf({}, g), nmea_, out_);
    } else {
      WriteTumLine(out_, e.x);
    }
    if (std::fflush(out_) != 0) throw std::runtime_error(std::string("stdout: write failed: ") + std::strerror(errno));
    ++written_;
  }

  uint64_t written() const { return written_; }
  uint64_t non_finite() const { return filter_.non_finite(); }

 private:
  std::FILE* out_;
  api::Stream stream_;
  std::string format_;
  NmeaExportOptions nmea_;
  double next_nmea_t_ = -1e300;
  std::optional<NearGeodetic> geodetic_;  // lla: the run's conversion, so that the lines are its file's
  StateFilter filter_;
  uint64_t written_ = 0;
};

// The end-of-stream report on stderr: what was read and skipped, what was written, and why it ended.
void Report(const ReadStats& rs, const StateLines& lines, api::Stream stream, int signal) {
  std::string skipped;
  for (const auto& [reason, n] : rs.skipped) skipped += " " + reason + " " + std::to_string(n);
  std::fprintf(
      stderr,
      "gins stream: %llu lines: %s records; %llu damaged lines skipped%s%s; %llu %s states written%s%s\n",
      static_cast<unsigned long long>(rs.lines), FormatRecordCounts(rs.records, ZeroCounts::kShow).c_str(),
      static_cast<unsigned long long>(rs.total_skipped()),
      skipped.empty() ? "" : " (", skipped.empty() ? "" : (skipped.substr(1) + ")").c_str(),
      static_cast<unsigned long long>(lines.written()), api::StreamName(stream),
      lines.non_finite() > 0 ? (", " + std::to_string(lines.non_finite()) + " not finite skipped").c_str() : "",
      signal != 0 ? (std::string("; input ended by SIG") + sigabbrev_np(signal)).c_str() : "");
}

}  // namespace

CLI::App* AddStreamCommand(CLI::App& app, StreamRequest* req) {
  auto* stream = app.add_subcommand("stream", "Estimate from records on stdin, each state on stdout as it comes");
  stream->footer(
      "Reads the log format of `gins run` (plain text; zcat a .gz log) with the same damage policy and\n"
      "writes the lines `gins run` writes to <stream>.tum (_states.csv, _lla.csv), each flushed as soon as the\n"
      "state is estimated: the ESKF's with the IMU sample, the smoother's final ones when their keyframe\n"
      "leaves the window (--online: its newest keyframe after each solve). Measurements that arrive out of\n"
      "order are sorted within input.reorder_window_s (which every state then waits for). Ends at the end of\n"
      "the input or on SIGINT/SIGTERM, after estimating and writing what was read (exit 0). A report goes\n"
      "to stderr.");
  stream->add_option("--config", req->config_path, "YAML config (see config/default.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  stream->add_option("--mode", req->mode, "Estimator")
      ->check(CLI::IsMember({"eskf", "smoother"}))
      ->capture_default_str();
  stream->add_option("--out-format", req->out_format,
                     "tum: t x y z qx qy qz qw; csv: the full state with 1-σ; lla: t, latitude, longitude, "
                     "height with 1-σ; nmea: GGA, RMC, GST, HDT at --rate (docs/formats.md §5)")
      ->check(CLI::IsMember({"tum", "csv", "lla", "nmea"}))
      ->capture_default_str();
  stream->add_option("--rate", req->rate_hz, "nmea: epochs per second (0: every state)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  stream->add_option("--time-scale", req->time_scale,
                     "nmea: the log's times are gps (seconds since 1980-01-06, GPS time) or unix (UTC) seconds")
      ->check(CLI::IsMember({"gps", "unix"}))
      ->capture_default_str();
  stream->add_flag("--online", req->online, "With --mode smoother: the causal estimate (smoother_online)");
  return stream;
}

int RunStream(const StreamRequest& req, int in_fd, std::FILE* out) {
  try {
    const api::Config config = api::Config::FromFile(req.config_path);
    api::SessionOptions session_options;
    if (!api::ParseMode(req.mode, &session_options.mode) || session_options.mode == api::Mode::kBoth) {
      throw std::invalid_argument("unknown or unsupported mode '" + req.mode + "'");
    }
    session_options.geodetic = false;  // the lines are in ENU
    const api::Stream stream = session_options.mode == api::Mode::kEskf ? api::Stream::kEskf
                               : req.online                             ? api::Stream::kSmootherOnline
                                                                        : api::Stream::kSmoother;
    StopSignals signals;
    api::LogReader reader = api::LogReader::FromFd(in_fd, kInputName, config, signals.fd());
    api::Session session(config, session_options);
    NmeaExportOptions nmea;
    nmea.rate_hz = req.rate_hz;
    ParseLogTimeScale(req.time_scale, &nmea.time_scale);
    StateLines lines(out, stream, req.out_format, nmea);
    session.OnState([&](const api::State& s) { lines.Add(s, session); });

    const double max_wait = api::internal::Access::options(config).init.max_wait;
    api::Record rec;
    while (reader.Next(&rec)) {
      session.Push(rec);
      CheckInitTimeout(kInputName, max_wait, session);
    }
    const ReadStats& read_stats = api::internal::Access::read_stats(reader);
    CheckReadCounts(kInputName, read_stats, !api::internal::Access::options(config).sensors.gnss.raw.obs_file.empty());
    FinishSession(kInputName, &session);
    Report(read_stats, lines, stream, reader.stopped() ? signals.Received() : 0);
    return 0;
  } catch (const std::exception& e) {
    std::fflush(out);
    std::fprintf(stderr, "gins: error: %s\n", e.what());
    return 1;
  }
}

}  // namespace gins
