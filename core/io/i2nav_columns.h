// Internals of the i2Nav converter (core/io/i2nav.h), exposed for it and its tests: per-file damage
// accounting under the gins reader's policy, and a reader of numeric columns with time-order checks.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/io/i2nav.h"
#include "core/io/text_input.h"

namespace gins {

std::string FormatText(const char* format, ...) __attribute__((format(printf, 1, 2)));

// Damage and warnings of one input file, counted into its ConvertedFile. Damage follows the gins reader's
// policy: under kStop the first damaged line throws; under kSkip it is counted and skipped, and more than
// max_errors throw. Messages: "<file>:<line>: <reason>: <detail>".
class FileIssues {
 public:
  FileIssues(ConvertedFile* file, const InputOptions& options) : file_(file), options_(options) {}
  void Damage(uint64_t line, const char* reason, const std::string& detail);
  void Warn(uint64_t line, const char* key, const std::string& detail);
  // A problem with the whole file, found at a line: throws "<file>:<line>: <message>" whatever the policy.
  [[noreturn]] void Refuse(uint64_t line, const std::string& message) const;

 private:
  void Example(uint64_t line, const char* reason, const std::string& detail, uint64_t count);
  ConvertedFile* file_;
  const InputOptions& options_;
  uint64_t skipped_ = 0;
};

// The columns a file format uses.
struct ColumnSpec {
  const char* what;   // "IMU" or "GNSS", for messages
  const char* usage;  // the expected columns, for messages, e.g. "7 columns: t dθx dθy dθz dvx dvy dvz"
  const char* const* names;  // names of the used columns, in the order Columns::v holds them
  size_t used;               // how many columns are used
  // Indices of the used columns in a line of `count` columns, or nullptr when that count is not the format.
  const int* (*select)(size_t count);
};

constexpr size_t kMaxColumns = 16;

// The used columns of one accepted line.
struct Columns {
  uint64_t line = 0;
  // Column 1, the time, in extended precision: an interval of 5 ms between times of ~4e5 s then keeps
  // ~1e-11 relative precision instead of double's ~1e-8.
  long double t = 0.0L;
  std::array<double, kMaxColumns> v{};  // the used columns in ColumnSpec order; v[0] is the time as a double
  size_t count = 0;                     // columns in the line
};

// Numeric lines of an i2Nav text file: fields split at spaces, tabs and commas (as KF-GINS's FileLoader
// splits them), blank lines and '#' or '%' comment lines skipped, plain or gzip. Every line of a file must
// have the same number of columns (the first good line fixes it). Times must be >= 0 and increase:
// an older time is out_of_order, a repeated one a duplicate.
class ColumnReader {
 public:
  ColumnReader(const ColumnSpec& spec, ConvertedFile* file, const InputOptions& options);
  bool Next(Columns* columns);  // the next accepted line; false at the end
  FileIssues& issues() { return issues_; }

 private:
  // nullptr when the line is good or blank (*blank), else the damage reason with *detail.
  const char* Parse(std::string_view text, Columns* c, bool* blank, std::string* detail);
  const char* CheckCount(size_t count, const int** select, std::string* detail) const;
  const char* CheckOrder(const Columns& c, std::string* detail) const;
  bool DamagedByReading(const TextLine& line);
  void EndOfData();

  const ColumnSpec spec_;
  ConvertedFile* file_;
  LineSource lines_;
  FileIssues issues_;
  bool have_last_ = false;
  long double last_t_ = 0.0L;
  bool stream_error_reported_ = false;
  bool done_ = false;
};

}  // namespace gins
