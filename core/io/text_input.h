// Text input primitives shared by the readers of line-based files (the gins log, core/io/log_reader.h, and
// the foreign formats of core/io/i2nav.h): a bounded-memory line source over a plain or gzip file, the
// strict number syntax, token quoting for messages, and the damage reason keys, so that every reader
// reports damage under the same names.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

struct gzFile_s;  // zlib's file handle (gzFile is gzFile_s*)

namespace gins {

// Bad or unreadable input at the program boundary. what() is one line: "<file>:<line>: <reason>" (or
// "<file>: <reason>" when no line applies).
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reason keys for a damaged line (ReadStats::skipped, the converters' summaries).
namespace input_reason {
inline constexpr char kBadNumber[] = "bad_number";
inline constexpr char kNonFinite[] = "non_finite";
inline constexpr char kMissingFields[] = "missing_fields";
inline constexpr char kExtraFields[] = "extra_fields";
inline constexpr char kUnknownType[] = "unknown_type";
inline constexpr char kOutOfOrder[] = "out_of_order";
inline constexpr char kDuplicate[] = "duplicate";
inline constexpr char kAbsurdValue[] = "absurd_value";
inline constexpr char kLineTooLong[] = "line_too_long";
inline constexpr char kTruncated[] = "truncated";
inline constexpr char kTimeJump[] = "time_jump";
}  // namespace input_reason

enum class NumberStatus { kOk, kBad, kNonFinite };

// The whole token must be a decimal floating-point number (strtod syntax minus hex; a leading '+' is
// allowed). Overflow ("1e400") is kNonFinite, underflow a legitimate tiny value. Locale-independent and
// allocation-free on the common path.
NumberStatus ParseNumber(std::string_view token, double* value);

// A token as it may appear in a one-line message: quoted, binary bytes escaped, long tokens shortened.
std::string QuoteToken(std::string_view token);

// One line of a text file.
struct TextLine {
  std::string_view text;   // without its "\n" or "\r\n"; valid until the next Next(); empty when too_long
  uint64_t number = 0;     // 1-based
  uint64_t length = 0;     // characters, without the line end
  bool terminated = true;  // ended by '\n' (false: the last line of the file)
  bool too_long = false;   // longer than the limit: dropped chunk by chunk, so memory stays bounded
};

// Lines of a plain or gzip file (detected by its magic bytes, not its name), a UTF-8 BOM skipped. Memory
// is bounded by the line-length limit whatever the file holds; lines are views into the read buffer, so a
// line costs no allocation.
class LineSource {
 public:
  // Throws InputError("<path>: cannot open: <why>") if the file cannot be opened (or is a directory).
  // max_line_length is clamped to [1, 16 MiB].
  LineSource(const std::string& path, int64_t max_line_length);
  // Lines of a pipe, socket or terminal as they arrive (`gins stream`'s stdin): each read returns what is
  // there, so a line is handed on as soon as its '\n' is (a file's reads wait for a whole chunk). Plain
  // text only (a live feed is not compressed: gzip data is refused with an InputError). fd stays open.
  // When stop_fd (>= 0; e.g. a signalfd for SIGINT and SIGTERM) becomes readable, the data ends after the
  // last complete line already read, and stopped() is true.
  LineSource(int fd, const std::string& name, int64_t max_line_length, int stop_fd = -1);
  ~LineSource();
  LineSource(const LineSource&) = delete;
  LineSource& operator=(const LineSource&) = delete;

  // The next line; false when there is no more data. The data may also end early: see read_errno() and
  // stream_error() (the caller decides how to report them).
  bool Next(TextLine* line);

  uint64_t lines() const { return line_no_; }  // lines returned so far
  size_t max_line() const { return max_line_; }
  const std::string& path() const { return path_; }
  // Non-zero when an I/O error ended the data (an errno value).
  int read_errno() const { return read_errno_; }
  // The gzip stream was cut short or is corrupt: the data ended early; message() says how.
  bool stream_error() const { return stream_error_; }
  const std::string& stream_message() const { return stream_message_; }
  // The data ended because stop_fd became readable.
  bool stopped() const { return stopped_; }

 private:
  struct GzClose {
    void operator()(gzFile_s* f) const;
  };
  bool SkipLongLine(TextLine* line);
  void Fill();
  void FillFromFd(size_t room);
  void Stop();

  const std::string path_;
  const size_t max_line_;
  std::vector<char> buf_;
  std::unique_ptr<gzFile_s, GzClose> file_;  // a file, or
  int fd_ = -1, stop_fd_ = -1;                 // a stream read as it arrives
  bool stopped_ = false;
  size_t begin_ = 0;  // unconsumed bytes are buf_[begin_, end_)
  size_t end_ = 0;
  bool at_start_ = true;  // nothing read yet (a UTF-8 BOM may follow)
  bool eof_ = false;      // zlib has nothing more to give
  bool stream_error_ = false;
  std::string stream_message_;
  int read_errno_ = 0;
  uint64_t line_no_ = 0;
};

}  // namespace gins
