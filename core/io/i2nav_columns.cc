#include "core/io/i2nav_columns.h"

#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/io/log_reader.h"

namespace gins {
namespace {

using input_reason::kAbsurdValue;
using input_reason::kBadNumber;
using input_reason::kDuplicate;
using input_reason::kExtraFields;
using input_reason::kLineTooLong;
using input_reason::kMissingFields;
using input_reason::kNonFinite;
using input_reason::kOutOfOrder;
using input_reason::kTruncated;

constexpr double kHalfWeek = 302400.0;  // s: a step back this large in seconds of week is a new GPS week

inline bool IsSeparator(char c) {
  return c == ' ' || c == '\t' || c == ',' || c == '\r' || c == '\v' || c == '\f';
}

// Column 1 in extended precision (strtold wants a terminated string: times are short tokens).
long double ParseTime(std::string_view token, double fallback) {
  char buf[64];
  if (token.size() >= sizeof(buf)) return fallback;
  std::memcpy(buf, token.data(), token.size());
  buf[token.size()] = '\0';
  char* end = nullptr;
  const long double t = std::strtold(buf, &end);
  return end == buf + token.size() ? t : fallback;
}

}  // namespace

std::string FormatText(const char* format, ...) {
  char buf[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buf, sizeof(buf), format, args);
  va_end(args);
  return buf;
}

uint64_t ConvertedFile::total_skipped() const {
  uint64_t total = 0;
  for (const auto& [reason, count] : skipped) total += count;
  return total;
}

void FileIssues::Example(uint64_t line, const char* reason, const std::string& detail, uint64_t count) {
  if (count <= static_cast<uint64_t>(ConvertedFile::kMaxExamplesPerReason)) {
    file_->issues.push_back(InputIssue{line, reason, detail});
  }
}

void FileIssues::Damage(uint64_t line, const char* reason, const std::string& detail) {
  ++skipped_;
  Example(line, reason, detail, ++file_->skipped[reason]);
  const std::string where = file_->path + ":" + std::to_string(line) + ": ";
  if (options_.on_error == InputErrorPolicy::kStop) throw InputError(where + reason + ": " + detail);
  if (options_.max_errors < 0 || skipped_ > static_cast<uint64_t>(options_.max_errors)) {
    throw InputError(where + "too many damaged lines (" + std::to_string(skipped_) + "), last: " + reason + ": " +
                     detail + " (max errors " + std::to_string(options_.max_errors) + ")");
  }
}

void FileIssues::Warn(uint64_t line, const char* key, const std::string& detail) {
  Example(line, key, detail, ++file_->warnings[key]);
}

void FileIssues::Refuse(uint64_t line, const std::string& message) const {
  throw InputError(file_->path + ":" + std::to_string(line) + ": " + message);
}

ColumnReader::ColumnReader(const ColumnSpec& spec, ConvertedFile* file, const InputOptions& options)
    : spec_(spec), file_(file), lines_(file->path, options.max_line_length), issues_(file, options) {}

const char* ColumnReader::CheckCount(size_t count, const int** select, std::string* detail) const {
  *select = count <= kMaxColumns ? spec_.select(count) : nullptr;
  if (*select == nullptr) {
    *detail = FormatText("%s line with %zu columns; the i2Nav %s file has %s", spec_.what, count, spec_.what,
                         spec_.usage);
    return count < spec_.used ? kMissingFields : kExtraFields;
  }
  if (file_->columns != 0 && count != static_cast<size_t>(file_->columns)) {
    *detail = FormatText("%zu columns where the file's first line has %d", count, file_->columns);
    return count < static_cast<size_t>(file_->columns) ? kMissingFields : kExtraFields;
  }
  return nullptr;
}

const char* ColumnReader::Parse(std::string_view text, Columns* c, bool* blank, std::string* detail) {
  std::array<std::string_view, kMaxColumns> tok;
  size_t count = 0;
  for (size_t i = 0; i < text.size();) {
    while (i < text.size() && IsSeparator(text[i])) ++i;
    if (i == text.size()) break;
    const size_t start = i;
    while (i < text.size() && !IsSeparator(text[i])) ++i;
    if (count < kMaxColumns) tok[count] = text.substr(start, i - start);
    ++count;
  }
  *blank = count == 0 || tok[0][0] == '#' || tok[0][0] == '%';
  if (*blank) return nullptr;
  const int* select = nullptr;
  if (const char* reason = CheckCount(count, &select, detail)) return reason;
  for (size_t k = 0; k < spec_.used; ++k) {
    const std::string_view token = tok[select[k]];
    const NumberStatus status = ParseNumber(token, &c->v[k]);
    if (status == NumberStatus::kOk) continue;
    *detail = FormatText("column %d (%s) %s is %s", select[k] + 1, spec_.names[k], QuoteToken(token).c_str(),
                         status == NumberStatus::kBad ? "not a number" : "not finite");
    return status == NumberStatus::kBad ? kBadNumber : kNonFinite;
  }
  c->t = ParseTime(tok[0], c->v[0]);
  c->count = count;
  return nullptr;
}

const char* ColumnReader::CheckOrder(const Columns& c, std::string* detail) const {
  if (c.t < 0.0L) {
    *detail = FormatText("column 1 (t) = %.6f, time must be >= 0", c.v[0]);
    return kAbsurdValue;
  }
  if (c.t >= static_cast<long double>(log_limits::kMaxTime)) {  // gins's reader would refuse it
    *detail = FormatText("column 1 (t) = %.6f, beyond %g s", c.v[0], log_limits::kMaxTime);
    return kAbsurdValue;
  }
  if (!have_last_ || c.t > last_t_) return nullptr;
  const double last = static_cast<double>(last_t_);
  if (c.t == last_t_) {
    *detail = FormatText("a second %s line at t = %.6f", spec_.what, last);
    return kDuplicate;
  }
  *detail = FormatText("t = %.6f is older than the previous line's %.6f", c.v[0], last);
  if (last - c.v[0] > kHalfWeek) {
    *detail += " (a GPS week rollover? i2Nav times are seconds of week: split the file at the new week)";
  }
  return kOutOfOrder;
}

bool ColumnReader::DamagedByReading(const TextLine& line) {
  if (line.too_long) {
    issues_.Damage(line.number, kLineTooLong,
                   FormatText("line of %llu characters, the limit is %zu", static_cast<unsigned long long>(line.length),
                              lines_.max_line()));
    return true;
  }
  if (line.terminated) return false;
  if (lines_.read_errno() != 0) {
    throw InputError(file_->path + ":" + std::to_string(line.number) + ": cannot read: " +
                     std::strerror(lines_.read_errno()));
  }
  if (lines_.stream_error()) {  // the last bytes of a cut gzip stream are a fragment even if they parse
    stream_error_reported_ = true;
    issues_.Damage(line.number, kTruncated,
                   "gzip stream cut short or corrupt (" + lines_.stream_message() + "), partial last line dropped");
    return true;
  }
  return false;
}

void ColumnReader::EndOfData() {
  done_ = true;
  if (lines_.read_errno() != 0) {
    throw InputError(file_->path + ":" + std::to_string(lines_.lines() + 1) + ": cannot read: " +
                     std::strerror(lines_.read_errno()));
  }
  if (lines_.stream_error() && !stream_error_reported_) {
    stream_error_reported_ = true;
    issues_.Damage(lines_.lines() + 1, kTruncated, "gzip stream cut short or corrupt (" + lines_.stream_message() + ")");
  }
}

bool ColumnReader::Next(Columns* c) {
  while (!done_) {
    TextLine line;
    if (!lines_.Next(&line)) {
      EndOfData();
      return false;
    }
    ++file_->lines;
    if (DamagedByReading(line)) continue;
    bool blank = false;
    std::string detail;
    const char* reason = Parse(line.text, c, &blank, &detail);
    if (blank) continue;
    if (reason == nullptr) reason = CheckOrder(*c, &detail);
    if (reason != nullptr) {
      // A last line without newline that fails is most likely cut mid-write (as the gins reader reads it).
      if (!line.terminated) {
        issues_.Damage(line.number, kTruncated,
                       "last line has no newline and is damaged: " + std::string(reason) + ": " + detail);
      } else {
        issues_.Damage(line.number, reason, detail);
      }
      continue;
    }
    if (file_->columns == 0) file_->columns = static_cast<int>(c->count);
    have_last_ = true;
    last_t_ = c->t;
    if (!file_->has_range) file_->t_first = c->v[0];
    file_->has_range = true;
    file_->t_last = c->v[0];
    c->line = line.number;
    return true;
  }
  return false;
}

}  // namespace gins
