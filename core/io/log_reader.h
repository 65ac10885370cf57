// Streaming reader of the gins log format (docs/formats.md §3): IMU / ODOM / GNSS / GVEL lines, optional σ
// columns, '#' comments, blank lines, CRLF, gzip (detected by magic bytes, not by name). Memory does not grow
// with the log. Damage policy (InputOptions::on_error):
//   skip (default): a damaged line is skipped and counted by reason, with its file:line kept for the
//                   summary (the first few per reason); reading goes on.
//   stop:           the first damaged line throws InputError naming file, line and reason.
// Reasons (keys in ReadStats::skipped): bad_number, non_finite, missing_fields, extra_fields,
// unknown_type, out_of_order, duplicate, absurd_value, line_too_long, truncated (last line without
// newline that does not parse, or a gzip stream cut short), time_jump.
// Time: records must be non-decreasing in time over the whole file; records of different types may share
// a time stamp in either order. A record older than the newest time read by more than
// input.reorder_window_s (default 0.1 s) is out_of_order; younger ones pass, and the API's reorder buffer
// (gins/gins.h) sorts them into place by the same rule. A record of the same type with the same time stamp
// as the previous one of that type is a duplicate. A record more than
// input.max_time_jump_s ahead of the newest time read is a time_jump (a corrupted far-future time stamp
// then costs one line, not every later one); after 10 consecutive records that all jumped and agree with
// each other, the log's clock really jumped and the reader takes the new time base.
// Code: ParseLogLine in log_line.cc, the streaming reader in log_reader.cc, the line source underneath in
// text_input.cc.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/io/log_record.h"
#include "core/io/text_input.h"
#include "core/measurements.h"

namespace gins {

enum class InputErrorPolicy { kSkip, kStop };

// Plausibility limits of a log record (ParseLogLine). Anything beyond them is a corrupted field, not a
// measurement. Gyro and acc are the defaults of the IMU's range (ImuRange below: imu.max_gyro_rad_s,
// imu.max_acc_m_s2), which a config may change; the rest are fixed. Writers of logs (core/io/i2nav.h) check
// against these defaults.
namespace log_limits {
inline constexpr double kMaxAbsGyro = 35.0;         // rad/s, per axis
inline constexpr double kMaxAbsAcc = 200.0;         // m/s², per axis
inline constexpr double kMaxAbsLatDeg = 90.0;       // inclusive
inline constexpr double kMaxAbsLonDeg = 180.0;      // inclusive
inline constexpr double kMinAlt = -1000.0;          // m, exclusive
inline constexpr double kMaxAlt = 1e5;              // m, exclusive
inline constexpr double kMaxSigma = 1e4;            // m, exclusive; σ must also be > 0 (a zero σ breaks a solver)
inline constexpr double kMaxAbsHeadingDeg = 360.0;  // inclusive; normalised into [0, 360)
inline constexpr double kMaxAbsPulses = 1e7;        // exclusive
inline constexpr double kMaxAbsSpeed = 1000.0;      // m/s, per axis of a GNSS velocity, inclusive
// Time stamps are seconds in (0, kMaxTime): 1e10 s is the year 2286 as Unix time, so a larger stamp is not in
// seconds (milliseconds or nanoseconds since the epoch) or is corrupted. The bound also keeps every interval
// between two records, and the fourth power of it that a coasted covariance takes, finite.
inline constexpr double kMaxTime = 1e10;            // s, exclusive
}  // namespace log_limits

// The IMU's measurement range, per axis: a reading beyond it is damage (absurd_value), not motion. The keys
// are the sensor's (imu.max_gyro_rad_s, imu.max_acc_m_s2: ImuOptions::max_gyro, max_acc); whoever opens a log
// with a config copies them in (ReaderOptions, config/options.h).
struct ImuRange {
  double max_gyro = log_limits::kMaxAbsGyro;  // rad/s
  double max_acc = log_limits::kMaxAbsAcc;    // m/s²
};

// input.*
struct InputOptions {
  InputErrorPolicy on_error = InputErrorPolicy::kSkip;  // input.on_error: skip | stop
  int max_errors = 1000;             // input.max_errors: give up after this many skipped lines (skip policy)
  int max_line_length = 4096;        // input.max_line_length: characters; longer lines are damage
  double max_time_jump = 60.0;       // input.max_time_jump_s: a record this far ahead of the newest time is
                                     // damage (time_jump); 0 = no limit
  double reorder_window = 0.1;       // input.reorder_window_s: a record this much older than the newest is
                                     // sorted into place; older ones are out_of_order
  bool regularize_stamps = true;     // input.regularize_stamps: IMU and wheel stamps put back on their
                                     // sensor's grid when a logger jittered them (core/io/sample_clock.h)
  ImuRange imu_range;                // not an input.* key: the imu.* range (ReaderOptions)
};

struct InputIssue {
  uint64_t line = 0;
  std::string reason;   // one of the reason keys
  std::string detail;   // human-readable, e.g. "field 3 'abc' is not a number"
};

// A converter's summary lines of its damage, one per reason: "    <kind> <reason>: <n> (first at line L:
// detail)\n", the detail of the first issue listed with that reason.
std::string FormatIssueCounts(const char* kind, const std::map<std::string, uint64_t>& counts,
                              const std::vector<InputIssue>& issues);

// "12 IMU, 3 ODOM, 2 GNSS, 0 GVEL" in the types' order; which zero counts it leaves out: none of the built-in
// types' (a measurement module's zero is always left out), all, or those of the types a log may well lack
// (RecordTypeInfo::quiet_when_none).
enum class ZeroCounts { kShow, kHide, kHideQuiet };
std::string FormatRecordCounts(const RecordCounts& counts, ZeroCounts zeros);

struct ReadStats {
  uint64_t lines = 0;
  RecordCounts records{};  // records accepted (CountOf<ImuSample>(records): the IMU's)
  std::map<std::string, uint64_t> skipped;  // reason -> count
  std::vector<InputIssue> examples;        // up to kMaxExamplesPerReason per reason
  // Every damaged line's number, by reason (at most input.max_errors + 1 in all: then the read stops).
  std::map<std::string, std::vector<uint64_t>> skipped_lines;
  static constexpr int kMaxExamplesPerReason = 5;
  uint64_t total_skipped() const;
};

// Parses one line of the log format (without its '\n'; a trailing '\r', comments and blanks are handled),
// with every check that needs no other line: syntax, field count, finiteness and absurd values. Time
// order (out_of_order, duplicate), line length and truncation need the file and are LogReader's job.
// Returns kRecord with *record filled (record->line untouched), kBlank for a blank or comment line, or
// kDamaged with issue->reason and issue->detail filled. Allocates only for a damaged line. Exposed for
// tests and the fuzzer.
enum class LineParse { kRecord, kBlank, kDamaged };
LineParse ParseLogLine(std::string_view line, LogRecord* record, InputIssue* issue, const ImuRange& range = {});

// The same checks on a record that did not come from a line (the API's pushes): every number finite, then
// ParseLogLine's range checks; on success the record is made what ParseLogLine would have made of it (a
// valid heading normalised into [0, 360), an invalid one 0). Returns kRecord or kDamaged with *issue filled.
LineParse CheckLogRecord(LogRecord* record, InputIssue* issue, const ImuRange& range = {});

class LogReader {
 public:
  // Throws InputError if the file cannot be opened or read.
  LogReader(const std::string& path, const InputOptions& options);
  // A stream read as it arrives (LineSource's fd constructor: plain text, each line handed on when its '\n'
  // is read, the end at EOF or when stop_fd becomes readable); `name` stands for the path in messages.
  LogReader(int fd, const std::string& name, const InputOptions& options, int stop_fd = -1);
  ~LogReader();
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;

  // Next accepted record; false at the end of the file. Throws InputError under the stop policy, when
  // more than options.max_errors lines were skipped, or when the file cannot be read.
  bool Next(LogRecord* record);

  const ReadStats& stats() const { return stats_; }
  const std::string& path() const { return path_; }
  // The stream ended because stop_fd became readable (not at EOF).
  bool stopped() const;

 private:
  class Impl;
  std::string path_;
  InputOptions options_;
  ReadStats stats_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gins
