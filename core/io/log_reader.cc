#include "core/io/log_reader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <system_error>
#include <utility>
#include <vector>

namespace gins {
namespace {

// Plausibility limits. The reader sees only InputOptions, so they are fixed here; gyro and acc match the
// ImuOptions defaults (max_gyro, max_acc). Anything beyond them is a corrupted field, not a measurement.
constexpr double kMaxAbsGyro = 35.0;         // rad/s, per axis
constexpr double kMaxAbsAcc = 200.0;         // m/s², per axis
constexpr double kMaxAbsLatDeg = 90.0;       // inclusive
constexpr double kMaxAbsLonDeg = 180.0;      // inclusive
constexpr double kMinAlt = -1000.0;          // m, exclusive
constexpr double kMaxAlt = 1e5;              // m, exclusive
constexpr double kMaxSigma = 1e4;            // m, exclusive; σ must also be > 0 (a zero σ breaks a solver)
constexpr double kMaxAbsHeadingDeg = 360.0;  // inclusive; normalised into [0, 360)
constexpr double kMaxAbsPulses = 1e7;        // exclusive

// Bytes asked of zlib per read; also zlib's own buffer size. Large reads keep the per-line cost low.
constexpr size_t kChunk = 256 * 1024;
// Cap on the line-length option so that a wild value cannot make the read buffer huge.
constexpr size_t kMaxLineLengthCap = 16u << 20;
// Longest piece of a token quoted in a detail message (messages stay one short line).
constexpr size_t kMaxQuoted = 32;

// Reason keys (ReadStats::skipped).
constexpr char kBadNumber[] = "bad_number";
constexpr char kNonFinite[] = "non_finite";
constexpr char kMissingFields[] = "missing_fields";
constexpr char kExtraFields[] = "extra_fields";
constexpr char kUnknownType[] = "unknown_type";
constexpr char kOutOfOrder[] = "out_of_order";
constexpr char kDuplicate[] = "duplicate";
constexpr char kAbsurdValue[] = "absurd_value";
constexpr char kLineTooLong[] = "line_too_long";
constexpr char kTruncated[] = "truncated";
constexpr char kTimeJump[] = "time_jump";

// After this many consecutive records that all jumped ahead (time_jump) and agree with each other, the clock
// of the log really jumped: the reader takes the new time base and reads on.
constexpr int kTimeJumpResync = 10;

// Names of the numeric fields after the type token, for messages.
constexpr const char* kImuFields[] = {"t", "gx", "gy", "gz", "ax", "ay", "az"};
constexpr const char* kOdomFields[] = {"t", "left_pulses", "right_pulses"};
constexpr const char* kGnssFields[] = {"t",       "lat",     "lon",    "alt", "heading", "heading_valid",
                                       "sigma_e", "sigma_n", "sigma_u"};
constexpr size_t kMaxNumbers = 9;               // GNSS with σ
constexpr size_t kMaxTokens = kMaxNumbers + 1;  // plus the type

inline bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Splits a line into whitespace-separated views without copying. count is the total number of tokens,
// which may exceed the kMaxTokens kept (enough to report extra fields).
struct Tokens {
  std::array<std::string_view, kMaxTokens> tok;
  size_t count = 0;
};

void Tokenize(std::string_view line, Tokens* tokens) {
  const char* p = line.data();
  const char* const end = p + line.size();
  tokens->count = 0;
  for (;;) {
    while (p < end && IsSpace(*p)) ++p;
    if (p == end) break;
    const char* const start = p;
    while (p < end && !IsSpace(*p)) ++p;
    if (tokens->count < kMaxTokens) tokens->tok[tokens->count] = std::string_view(start, p - start);
    ++tokens->count;
  }
}

// A token as it may appear in a message: binary bytes escaped, long tokens shortened.
std::string Quote(std::string_view token) {
  std::string out = "'";
  const size_t n = std::min(token.size(), kMaxQuoted);
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f && c != '\'' && c != '\\') {
      out.push_back(static_cast<char>(c));
    } else {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", c);
      out += hex;
    }
  }
  if (token.size() > n) out += "...";
  out.push_back('\'');
  return out;
}

enum class NumberStatus { kOk, kBad, kNonFinite };

// The whole token must be a decimal floating-point number (strtod syntax minus hex; a leading '+' is
// allowed). from_chars is locale-independent and allocation-free.
NumberStatus ParseNumber(std::string_view token, double* value) {
  const char* first = token.data();
  const char* const last = first + token.size();
  if (first != last && *first == '+') {
    ++first;
    if (first != last && *first == '-') return NumberStatus::kBad;  // "+-1"
  }
  if (first == last) return NumberStatus::kBad;
  const std::from_chars_result r = std::from_chars(first, last, *value);
  if (r.ptr != last) return NumberStatus::kBad;
  if (r.ec == std::errc::result_out_of_range) {
    // Overflow ("1e400") is not finite; underflow ("1e-400") is a legitimate tiny value. Only strtod
    // tells them apart and gives the rounded value; this path is rare, so the copy does not matter.
    const std::string copy(first, last);
    *value = std::strtod(copy.c_str(), nullptr);
    return std::isfinite(*value) ? NumberStatus::kOk : NumberStatus::kNonFinite;
  }
  if (r.ec != std::errc()) return NumberStatus::kBad;
  return std::isfinite(*value) ? NumberStatus::kOk : NumberStatus::kNonFinite;
}

LineParse Damaged(InputIssue* issue, const char* reason, std::string detail) {
  issue->reason = reason;
  issue->detail = std::move(detail);
  return LineParse::kDamaged;
}

// "field 4 (gy) = 40 rad/s, beyond ±35": fields are numbered like awk's, the type being field 1.
std::string FieldValue(size_t index, const char* name, double value) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "field %zu (%s) = %.10g", index + 2, name, value);
  return buf;
}

std::string Num(double value) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%g", value);
  return buf;
}

std::string Time(double t) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.6f", t);
  return buf;
}

const char* TypeName(LogRecord::Type type) {
  switch (type) {
    case LogRecord::Type::kImu:
      return "IMU";
    case LogRecord::Type::kOdom:
      return "ODOM";
    case LogRecord::Type::kGnss:
      return "GNSS";
  }
  return "?";
}

// Range checks on parsed numbers; returns the detail of the first absurd field, or empty.
std::string CheckImu(const double* v) {
  for (size_t i = 1; i <= 3; ++i) {
    if (std::abs(v[i]) > kMaxAbsGyro) {
      return FieldValue(i, kImuFields[i], v[i]) + " rad/s, beyond ±" + Num(kMaxAbsGyro);
    }
  }
  for (size_t i = 4; i <= 6; ++i) {
    if (std::abs(v[i]) > kMaxAbsAcc) {
      return FieldValue(i, kImuFields[i], v[i]) + " m/s², beyond ±" + Num(kMaxAbsAcc);
    }
  }
  return {};
}

std::string CheckOdom(const double* v) {
  for (size_t i = 1; i <= 2; ++i) {
    if (!(std::abs(v[i]) < kMaxAbsPulses)) {
      return FieldValue(i, kOdomFields[i], v[i]) + ", |pulses| must be < " + Num(kMaxAbsPulses);
    }
  }
  return {};
}

std::string CheckGnss(const double* v, size_t n) {
  if (std::abs(v[1]) > kMaxAbsLatDeg) {
    return FieldValue(1, "lat", v[1]) + " deg, beyond ±" + Num(kMaxAbsLatDeg);
  }
  if (std::abs(v[2]) > kMaxAbsLonDeg) {
    return FieldValue(2, "lon", v[2]) + " deg, beyond ±" + Num(kMaxAbsLonDeg);
  }
  if (!(v[3] > kMinAlt && v[3] < kMaxAlt)) {
    return FieldValue(3, "alt", v[3]) + " m, outside (" + Num(kMinAlt) + ", " + Num(kMaxAlt) + ")";
  }
  if (v[5] != 0.0 && v[5] != 1.0) return FieldValue(5, "heading_valid", v[5]) + ", must be 0 or 1";
  // An invalid heading is a placeholder the receiver may fill with anything; the fix is still a position.
  if (v[5] == 1.0 && std::abs(v[4]) > kMaxAbsHeadingDeg) {
    return FieldValue(4, "heading", v[4]) + " deg, outside ±" + Num(kMaxAbsHeadingDeg);
  }
  for (size_t i = 6; i < n; ++i) {
    if (!(v[i] > 0.0 && v[i] < kMaxSigma)) {
      return FieldValue(i, kGnssFields[i], v[i]) + " m, σ must be in (0, " + Num(kMaxSigma) + ")";
    }
  }
  return {};
}

// Heading in [-360, 360] -> [0, 360).
double NormaliseHeading(double h) {
  h = std::fmod(h, 360.0);
  if (h < 0.0) h += 360.0;
  if (h >= 360.0 || h == 0.0) h = 0.0;  // -1e-20 + 360 rounds to 360; -0 becomes +0
  return h;
}

}  // namespace

double LogRecord::t() const {
  switch (type) {
    case Type::kImu:
      return imu.t;
    case Type::kOdom:
      return odom.t;
    case Type::kGnss:
      return gnss.t;
  }
  return imu.t;
}

uint64_t ReadStats::total_skipped() const {
  uint64_t total = 0;
  for (const auto& [reason, count] : skipped) total += count;
  return total;
}

LineParse ParseLogLine(std::string_view line, LogRecord* record, InputIssue* issue) {
  if (const void* hash = std::memchr(line.data(), '#', line.size())) {
    line = line.substr(0, static_cast<const char*>(hash) - line.data());
  }
  Tokens tokens;
  Tokenize(line, &tokens);
  if (tokens.count == 0) return LineParse::kBlank;

  const std::string_view type = tokens.tok[0];
  const char* const* names = nullptr;
  size_t expected = 0;  // numbers after the type (GNSS: 6, or 9 with σ)
  if (type == "IMU") {
    record->type = LogRecord::Type::kImu;
    names = kImuFields;
    expected = 7;
  } else if (type == "ODOM") {
    record->type = LogRecord::Type::kOdom;
    names = kOdomFields;
    expected = 3;
  } else if (type == "GNSS") {
    record->type = LogRecord::Type::kGnss;
    names = kGnssFields;
    expected = tokens.count - 1 >= 9 ? 9 : 6;
  } else {
    return Damaged(issue, kUnknownType,
                   "unknown record type " + Quote(type) + " (expected IMU, ODOM or GNSS)");
  }

  // Field counts are of the values after the type; the message lists what the type needs.
  const size_t n = tokens.count - 1;
  const bool gnss = record->type == LogRecord::Type::kGnss;
  if (gnss && (n == 7 || n == 8)) {
    return Damaged(
        issue, kMissingFields,
        "GNSS has " + std::to_string(n) + " values; sigma_e sigma_n sigma_u come all three or none");
  }
  if (n != expected) {
    std::string detail = std::string(TypeName(record->type)) + " has " + std::to_string(n) +
                         " values, needs " + (gnss ? "6 or 9" : std::to_string(expected)) + ":";
    for (size_t i = 0; i < (gnss ? 9 : expected); ++i) detail += std::string(" ") + names[i];
    if (gnss) detail += " (sigma optional)";
    return Damaged(issue, n < expected ? kMissingFields : kExtraFields, std::move(detail));
  }

  double v[kMaxNumbers];
  for (size_t i = 0; i < n; ++i) {
    const NumberStatus status = ParseNumber(tokens.tok[i + 1], &v[i]);
    if (status == NumberStatus::kOk) continue;
    const std::string field =
        "field " + std::to_string(i + 2) + " (" + names[i] + ") " + Quote(tokens.tok[i + 1]);
    if (status == NumberStatus::kBad) return Damaged(issue, kBadNumber, field + " is not a number");
    return Damaged(issue, kNonFinite, field + " is not finite");
  }

  if (!(v[0] > 0.0)) return Damaged(issue, kAbsurdValue, FieldValue(0, "t", v[0]) + ", time must be > 0");
  std::string absurd;
  switch (record->type) {
    case LogRecord::Type::kImu:
      absurd = CheckImu(v);
      break;
    case LogRecord::Type::kOdom:
      absurd = CheckOdom(v);
      break;
    case LogRecord::Type::kGnss:
      absurd = CheckGnss(v, n);
      break;
  }
  if (!absurd.empty()) return Damaged(issue, kAbsurdValue, std::move(absurd));

  switch (record->type) {
    case LogRecord::Type::kImu:
      record->imu.t = v[0];
      record->imu.gyro = Vec3(v[1], v[2], v[3]);
      record->imu.acc = Vec3(v[4], v[5], v[6]);
      break;
    case LogRecord::Type::kOdom:
      record->odom.t = v[0];
      record->odom.left_pulses = v[1];
      record->odom.right_pulses = v[2];
      break;
    case LogRecord::Type::kGnss: {
      GnssRecord& g = record->gnss;
      g.t = v[0];
      g.lat_deg = v[1];
      g.lon_deg = v[2];
      g.alt_m = v[3];
      g.heading_valid = v[5] == 1.0;
      g.heading_deg = g.heading_valid ? NormaliseHeading(v[4]) : 0.0;
      g.has_sigma = n == 9;
      g.sigma_enu = g.has_sigma ? Vec3(v[6], v[7], v[8]) : Vec3::Zero();
      break;
    }
  }
  return LineParse::kRecord;
}

// The file, a bounded read buffer, and the reading state. Lines are views into the buffer: no copy and
// no allocation per line.
class LogReader::Impl {
 public:
  Impl(gzFile file, const std::string& path, const InputOptions& options, ReadStats* stats)
      : path_(path),
        options_(options),
        stats_(stats),
        max_line_(static_cast<size_t>(std::clamp<int64_t>(options.max_line_length, 1, kMaxLineLengthCap))),
        // Room for a whole line of max_line_ (+ "\r" not yet followed by its "\n") plus a full chunk.
        buf_(max_line_ + 2 + kChunk),
        file_(file) {}

  bool Next(LogRecord* record);

 private:
  enum class LineKind { kLine, kTooLong, kEnd };
  struct Line {
    std::string_view text;
    uint64_t number = 0;
    uint64_t length = 0;     // characters, without the "\r\n"
    bool terminated = true;  // ended by '\n' (false: last line of the file)
  };
  struct GzClose {
    void operator()(gzFile f) const { gzclose(f); }
  };

  LineKind NextLine(Line* line);
  LineKind SkipLongLine(Line* line);
  void Fill();
  void Damage(uint64_t line, const char* reason, const std::string& detail);
  [[noreturn]] void ThrowReadError(uint64_t line);

  const std::string& path_;
  const InputOptions& options_;
  ReadStats* stats_;
  const size_t max_line_;
  std::vector<char> buf_;
  // Owns the file once constructed; declared after buf_ so that a failed allocation leaves the closing
  // to the caller.
  std::unique_ptr<gzFile_s, GzClose> file_;
  size_t begin_ = 0;  // unconsumed bytes are buf_[begin_, end_)
  size_t end_ = 0;
  bool at_start_ = true;       // nothing read yet (a UTF-8 BOM may follow)
  bool eof_ = false;           // zlib has nothing more to give
  bool stream_error_ = false;  // gzip stream cut short or corrupt
  bool stream_error_reported_ = false;
  std::string stream_message_;
  int read_errno_ = 0;  // an I/O error ends the read
  bool done_ = false;
  uint64_t line_no_ = 0;
  uint64_t skipped_ = 0;
  // Time order: the newest accepted time, and the last accepted time per record type.
  bool have_newest_ = false;
  double newest_t_ = 0.0;
  std::array<bool, 3> have_last_{};
  std::array<double, 3> last_t_{};
  // Consecutive time_jump records that agree with each other (a real jump of the log's clock).
  int jump_run_ = 0;
  double jump_last_t_ = 0.0;
  InputIssue issue_;  // reused so that good lines allocate nothing
};

void LogReader::Impl::Fill() {
  if (begin_ > 0) {
    std::memmove(buf_.data(), buf_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  const size_t room = buf_.size() - end_;  // >= kChunk: callers compact lines shorter than max_line_ + 2
  errno = 0;
  const int n = gzread(file_.get(), buf_.data() + end_, static_cast<unsigned>(room));
  const int saved_errno = errno;
  if (n > 0) {
    end_ += static_cast<size_t>(n);
    if (at_start_ && end_ >= 3 && std::memcmp(buf_.data(), "\xEF\xBB\xBF", 3) == 0) {
      begin_ = 3;  // a UTF-8 BOM some editors write
    }
    at_start_ = false;
    return;
  }
  eof_ = true;
  int err = Z_OK;
  const char* message = gzerror(file_.get(), &err);
  if (err == Z_ERRNO) {
    read_errno_ = saved_errno != 0 ? saved_errno : EIO;
  } else if (err != Z_OK) {
    // Z_BUF_ERROR: the stream ends inside a member ("unexpected end of file"); Z_DATA_ERROR: corrupt data
    // or check value. Either way nothing more can be read.
    stream_error_ = true;
    stream_message_ = message != nullptr ? message : "gzip error";
    // zlib prefixes its message with the "path" it was given, "<fd:N>" for gzdopen: noise to a user.
    if (stream_message_.rfind("<fd:", 0) == 0) {
      const size_t colon = stream_message_.find(": ");
      if (colon != std::string::npos) stream_message_.erase(0, colon + 2);
    }
  }
}

LogReader::Impl::LineKind LogReader::Impl::NextLine(Line* line) {
  for (;;) {
    const char* const start = buf_.data() + begin_;
    const size_t pending = end_ - begin_;
    const char* const newline =
        pending > 0 ? static_cast<const char*>(std::memchr(start, '\n', pending)) : nullptr;
    if (newline != nullptr || (eof_ && pending > 0)) {
      size_t length = newline != nullptr ? static_cast<size_t>(newline - start) : pending;
      begin_ += newline != nullptr ? length + 1 : length;
      if (length > 0 && start[length - 1] == '\r') --length;
      line->number = ++line_no_;
      line->length = length;
      line->terminated = newline != nullptr;
      line->text = std::string_view(start, length);
      return length > max_line_ ? LineKind::kTooLong : LineKind::kLine;
    }
    // pending bytes without a '\n' are already too long even if the next two bytes are "\r\n".
    if (pending > max_line_ + 1) return SkipLongLine(line);
    if (eof_) return LineKind::kEnd;
    Fill();
  }
}

// Drops the rest of an overlong line chunk by chunk, so memory stays bounded whatever its length.
LogReader::Impl::LineKind LogReader::Impl::SkipLongLine(Line* line) {
  uint64_t length = end_ - begin_;
  begin_ = end_ = 0;
  line->number = ++line_no_;
  line->text = {};
  for (;;) {
    if (eof_) {
      line->terminated = false;
      line->length = length;
      return LineKind::kTooLong;
    }
    Fill();
    const char* const start = buf_.data() + begin_;
    const size_t pending = end_ - begin_;
    const char* const newline =
        pending > 0 ? static_cast<const char*>(std::memchr(start, '\n', pending)) : nullptr;
    if (newline != nullptr) {
      const size_t n = static_cast<size_t>(newline - start);
      begin_ += n + 1;
      line->terminated = true;
      line->length = length + n - (n > 0 && start[n - 1] == '\r' ? 1 : 0);
      return LineKind::kTooLong;
    }
    length += pending;
    begin_ = end_ = 0;
  }
}

void LogReader::Impl::ThrowReadError(uint64_t line) {
  done_ = true;
  throw InputError(path_ + ":" + std::to_string(line) + ": cannot read: " + std::strerror(read_errno_));
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
    throw InputError(where + "too many damaged lines (" + std::to_string(skipped_) + "), last: " + reason +
                     " (input.max_errors = " + std::to_string(options_.max_errors) + ")");
  }
}

bool LogReader::Impl::Next(LogRecord* record) {
  while (!done_) {
    Line line;
    const LineKind kind = NextLine(&line);
    if (kind == LineKind::kEnd) {
      if (read_errno_ != 0) ThrowReadError(line_no_ + 1);
      done_ = true;
      if (stream_error_ && !stream_error_reported_) {
        stream_error_reported_ = true;
        Damage(line_no_ + 1, kTruncated, "gzip stream cut short or corrupt (" + stream_message_ + ")");
      }
      return false;
    }
    ++stats_->lines;
    if (kind == LineKind::kTooLong) {
      Damage(line.number, kLineTooLong,
             "line of " + std::to_string(line.length) + " characters, input.max_line_length is " +
                 std::to_string(max_line_));
      continue;
    }
    if (!line.terminated) {
      if (read_errno_ != 0) ThrowReadError(line.number);
      // The last bytes of a cut gzip stream are a fragment even when they happen to parse.
      if (stream_error_) {
        stream_error_reported_ = true;
        Damage(line.number, kTruncated,
               "gzip stream cut short or corrupt (" + stream_message_ + "), partial last line dropped");
        continue;
      }
    }

    const LineParse parsed = ParseLogLine(line.text, record, &issue_);
    if (parsed == LineParse::kBlank) continue;
    const char* reason = nullptr;
    std::string detail;
    if (parsed == LineParse::kDamaged) {
      reason = issue_.reason.c_str();
      detail = issue_.detail;
    } else {
      const size_t k = static_cast<size_t>(record->type);
      const double t = record->t();
      const double max_jump = options_.max_time_jump;
      if (have_newest_ && t < newest_t_) {
        reason = kOutOfOrder;
        detail = "t = " + Time(t) + " is older than the newest time read, " + Time(newest_t_);
      } else if (have_newest_ && max_jump > 0.0 && t - newest_t_ > max_jump) {
        const bool agrees = jump_run_ > 0 && t >= jump_last_t_ && t - jump_last_t_ <= max_jump;
        jump_run_ = agrees ? jump_run_ + 1 : 1;
        jump_last_t_ = t;
        if (jump_run_ < kTimeJumpResync) {
          reason = kTimeJump;
          char buf[160];
          std::snprintf(buf, sizeof(buf),
                        "t = %.6f is %.6g s ahead of the newest time read, %.6f (input.max_time_jump_s = %g)", t,
                        t - newest_t_, newest_t_, max_jump);
          detail = buf;
        } else {
          // The log's clock jumped: this record starts the new time base (the previous ones were counted).
          jump_run_ = 0;
          std::fill(have_last_.begin(), have_last_.end(), false);
        }
      } else if (have_last_[k] && t == last_t_[k]) {
        reason = kDuplicate;
        detail = std::string("a second ") + TypeName(record->type) + " record at t = " + Time(t);
      }
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

    const size_t k = static_cast<size_t>(record->type);
    jump_run_ = 0;  // a record in time order ends any run of jumped ones
    newest_t_ = record->t();
    have_newest_ = true;
    last_t_[k] = newest_t_;
    have_last_[k] = true;
    record->line = line.number;
    switch (record->type) {
      case LogRecord::Type::kImu:
        ++stats_->imu;
        break;
      case LogRecord::Type::kOdom:
        ++stats_->odom;
        break;
      case LogRecord::Type::kGnss:
        ++stats_->gnss;
        break;
    }
    return true;
  }
  return false;
}

LogReader::LogReader(const std::string& path, const InputOptions& options) : path_(path), options_(options) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(path + ": cannot open: " + std::strerror(errno));
  struct stat st;
  if (::fstat(fd, &st) == 0 && S_ISDIR(st.st_mode)) {
    ::close(fd);
    throw InputError(path + ": cannot open: " + std::strerror(EISDIR));
  }
  // zlib reads gzip (recognised by its magic bytes, whatever the name) and passes anything else through.
  gzFile file = gzdopen(fd, "rb");
  if (file == nullptr) {
    ::close(fd);
    throw InputError(path + ": cannot open: out of memory");
  }
  gzbuffer(file, kChunk);  // before the first read
  try {
    impl_ = std::make_unique<Impl>(file, path_, options_, &stats_);
  } catch (...) {
    gzclose(file);
    throw;
  }
}

LogReader::~LogReader() = default;

bool LogReader::Next(LogRecord* record) { return impl_->Next(record); }

}  // namespace gins
