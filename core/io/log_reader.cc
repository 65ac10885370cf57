// LogReader (core/io/log_reader.h): the streaming reader of the gins log, with the time-order and damage
// policy; lines come from LineSource (core/io/text_input.h), each parsed by ParseLogLine (log_line.cc).
#include "core/io/log_reader.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>

namespace gins {
namespace {

using input_reason::kDuplicate;
using input_reason::kLineTooLong;
using input_reason::kOutOfOrder;
using input_reason::kTimeJump;
using input_reason::kTruncated;

// After this many consecutive records that all jumped ahead (time_jump) and agree with each other, the clock
// of the log really jumped: the reader takes the new time base and reads on.
constexpr int kTimeJumpResync = 10;

std::string Time(double t) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.6f", t);
  return buf;
}

}  // namespace

uint64_t ReadStats::total_skipped() const {
  uint64_t total = 0;
  for (const auto& [reason, count] : skipped) total += count;
  return total;
}

// The line source and the reading state.
class LogReader::Impl {
 public:
  Impl(const std::string& path, const InputOptions& options, ReadStats* stats)
      : path_(path), options_(options), stats_(stats), lines_(path, options.max_line_length) {}
  Impl(int fd, const std::string& name, const InputOptions& options, ReadStats* stats, int stop_fd)
      : path_(name), options_(options), stats_(stats), lines_(fd, name, options.max_line_length, stop_fd) {}

  bool Next(LogRecord* record);
  bool stopped() const { return lines_.stopped(); }

 private:
  // Handles a line that cannot be parsed as it stands (too long, or the cut last line); true if it was one.
  bool DamagedByReading(const TextLine& line);
  // Time-order checks of a parsed record; sets *reason and *detail when it must be skipped.
  void CheckTime(const LogRecord& record, const char** reason, std::string* detail);
  void Accept(LogRecord* record, uint64_t line);
  void Damage(uint64_t line, const char* reason, const std::string& detail);
  [[noreturn]] void ThrowReadError(uint64_t line);

  const std::string& path_;
  const InputOptions& options_;
  ReadStats* stats_;
  LineSource lines_;
  bool stream_error_reported_ = false;
  bool done_ = false;
  uint64_t skipped_ = 0;
  // Time order: the newest accepted time, and the last accepted time per record type.
  bool have_newest_ = false;
  double newest_t_ = 0.0;
  std::array<bool, kNumRecordTypes> have_last_{};
  std::array<double, kNumRecordTypes> last_t_{};
  // Consecutive time_jump records that agree with each other (a real jump of the log's clock).
  int jump_run_ = 0;
  double jump_last_t_ = 0.0;
  InputIssue issue_;  // reused so that good lines allocate nothing
};

void LogReader::Impl::ThrowReadError(uint64_t line) {
  done_ = true;
  throw InputError(path_ + ":" + std::to_string(line) + ": cannot read: " + std::strerror(lines_.read_errno()));
}

void LogReader::Impl::Damage(uint64_t line, const char* reason, const std::string& detail) {
  ++skipped_;
  const uint64_t count = ++stats_->skipped[reason];
  stats_->skipped_lines[reason].push_back(line);
  if (count <= static_cast<uint64_t>(ReadStats::kMaxExamplesPerReason)) {
    stats_->examples.push_back(InputIssue{line, reason, detail});
  }
  const std::string where = path_ + ":" + std::to_string(line) + ": ";
  if (options_.on_error == InputErrorPolicy::kStop) {
    done_ = true;
    throw InputError(where + reason + ": " + detail);
  }
  if (options_.max_errors < 0 || skipped_ > static_cast<uint64_t>(options_.max_errors)) {
    done_ = true;
    // The last line's detail too: it names the cause (time in ms: "not seconds?") as on_error: stop would.
    throw InputError(where + "too many damaged lines (" + std::to_string(skipped_) + "), last: " + reason + ": " +
                     detail + " (input.max_errors = " + std::to_string(options_.max_errors) + ")");
  }
}

bool LogReader::Impl::DamagedByReading(const TextLine& line) {
  if (line.too_long) {
    Damage(line.number, kLineTooLong,
           "line of " + std::to_string(line.length) + " characters, input.max_line_length is " +
               std::to_string(lines_.max_line()));
    return true;
  }
  if (line.terminated) return false;
  if (lines_.read_errno() != 0) ThrowReadError(line.number);
  // The last bytes of a cut gzip stream are a fragment even when they happen to parse.
  if (lines_.stream_error()) {
    stream_error_reported_ = true;
    Damage(line.number, kTruncated,
           "gzip stream cut short or corrupt (" + lines_.stream_message() + "), partial last line dropped");
    return true;
  }
  return false;
}

void LogReader::Impl::CheckTime(const LogRecord& record, const char** reason, std::string* detail) {
  const size_t k = record.type_index();
  const double t = record.t();
  const double max_jump = options_.max_time_jump;
  if (have_newest_ && t < newest_t_ - options_.reorder_window) {
    *reason = kOutOfOrder;
    *detail = "t = " + Time(t) + " is older than the newest time read, " + Time(newest_t_);
    if (options_.reorder_window > 0.0) *detail += ", by more than input.reorder_window_s";
  } else if (have_newest_ && max_jump > 0.0 && t - newest_t_ > max_jump) {
    const bool agrees = jump_run_ > 0 && t >= jump_last_t_ && t - jump_last_t_ <= max_jump;
    jump_run_ = agrees ? jump_run_ + 1 : 1;
    jump_last_t_ = t;
    if (jump_run_ < kTimeJumpResync) {
      *reason = kTimeJump;
      char buf[160];
      std::snprintf(buf, sizeof(buf),
                    "t = %.6f is %.6g s ahead of the newest time read, %.6f (input.max_time_jump_s = %g)", t,
                    t - newest_t_, newest_t_, max_jump);
      *detail = buf;
    } else {
      // The log's clock jumped: this record starts the new time base (the previous ones were counted).
      jump_run_ = 0;
      std::fill(have_last_.begin(), have_last_.end(), false);
    }
  } else if (have_last_[k] && t == last_t_[k]) {
    *reason = kDuplicate;
    *detail = std::string("a second ") + record.info().token + " record at t = " + Time(t);
  }
}

void LogReader::Impl::Accept(LogRecord* record, uint64_t line) {
  const size_t k = record->type_index();
  jump_run_ = 0;  // a record in time order ends any run of jumped ones
  // Within the reorder window a record may be older than the newest one.
  newest_t_ = have_newest_ ? std::max(newest_t_, record->t()) : record->t();
  have_newest_ = true;
  // Its own time: a record read ahead of the others (reorder window) is no duplicate of theirs.
  last_t_[k] = record->t();
  have_last_[k] = true;
  record->line = line;
  ++stats_->records[k];
}

bool LogReader::Impl::Next(LogRecord* record) {
  while (!done_) {
    TextLine line;
    if (!lines_.Next(&line)) {
      if (lines_.read_errno() != 0) ThrowReadError(lines_.lines() + 1);
      done_ = true;
      if (lines_.stream_error() && !stream_error_reported_) {
        stream_error_reported_ = true;
        Damage(lines_.lines() + 1, kTruncated,
               "gzip stream cut short or corrupt (" + lines_.stream_message() + ")");
      }
      return false;
    }
    ++stats_->lines;
    if (DamagedByReading(line)) continue;

    const LineParse parsed = ParseLogLine(line.text, record, &issue_, options_.imu_range);
    if (parsed == LineParse::kBlank) continue;
    const char* reason = nullptr;
    std::string detail;
    if (parsed == LineParse::kDamaged) {
      reason = issue_.reason.c_str();
      detail = issue_.detail;
    } else {
      CheckTime(*record, &reason, &detail);
    }
    if (reason != nullptr) {
      // A last line without newline that fails is most likely cut mid-write, whatever it then looks like.
      if (!line.terminated) {
        Damage(line.number, kTruncated,
               "last line has no newline and is damaged: " + std::string(reason) + ": " + detail);
      } else {
        Damage(line.number, reason, detail);
      }
      continue;
    }
    Accept(record, line.number);
    return true;
  }
  return false;
}

LogReader::LogReader(const std::string& path, const InputOptions& options) : path_(path), options_(options) {
  impl_ = std::make_unique<Impl>(path_, options_, &stats_);
}

LogReader::LogReader(int fd, const std::string& name, const InputOptions& options, int stop_fd)
    : path_(name), options_(options) {
  impl_ = std::make_unique<Impl>(fd, path_, options_, &stats_, stop_fd);
}

LogReader::~LogReader() = default;

bool LogReader::stopped() const { return impl_->stopped(); }

bool LogReader::Next(LogRecord* record) { return impl_->Next(record); }

std::string FormatRecordCounts(const RecordCounts& counts, ZeroCounts zeros) {
  std::string out;
  for (size_t k = 0; k < kNumRecordTypes; ++k) {
    const bool module = k >= kNumRecordTypes - MeasurementModules::kSize;
    const bool hidden = zeros == ZeroCounts::kHide || module ||
                        (zeros == ZeroCounts::kHideQuiet && kRecordTypes[k].quiet_when_none);
    if (counts[k] == 0 && hidden) continue;
    out += (out.empty() ? "" : ", ") + std::to_string(counts[k]) + " " + kRecordTypes[k].token;
  }
  return out;
}

std::string FormatIssueCounts(const char* kind, const std::map<std::string, uint64_t>& counts,
                              const std::vector<InputIssue>& issues) {
  std::string out;
  for (const auto& [reason, n] : counts) {
    out += std::string("    ") + kind + " " + reason + ": " + std::to_string(n);
    for (const InputIssue& issue : issues) {
      if (issue.reason != reason) continue;
      out += " (first at line " + std::to_string(issue.line) + ": " + issue.detail + ")";
      break;
    }
    out += "\n";
  }
  return out;
}

}  // namespace gins
