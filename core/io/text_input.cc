#include "core/io/text_input.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <system_error>

namespace gins {
namespace {

// Bytes asked of zlib per read; also zlib's own buffer size. Large reads keep the per-line cost low.
constexpr size_t kChunk = 256 * 1024;
// Cap on the line-length limit so that a wild value cannot make the read buffer huge.
constexpr int64_t kMaxLineLengthCap = 16 << 20;
// Longest piece of a token quoted in a message (messages stay one short line).
constexpr size_t kMaxQuoted = 32;

}  // namespace

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

std::string QuoteToken(std::string_view token) {
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

void LineSource::GzClose::operator()(gzFile_s* f) const { gzclose(f); }

LineSource::LineSource(const std::string& path, int64_t max_line_length)
    : path_(path),
      max_line_(static_cast<size_t>(std::clamp<int64_t>(max_line_length, 1, kMaxLineLengthCap))),
      // Room for a whole line of max_line_ (+ "\r" not yet followed by its "\n") plus a full chunk.
      buf_(max_line_ + 2 + kChunk) {
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
  file_.reset(file);
  gzbuffer(file, kChunk);  // before the first read
}

LineSource::LineSource(int fd, const std::string& name, int64_t max_line_length, int stop_fd)
    : path_(name),
      max_line_(static_cast<size_t>(std::clamp<int64_t>(max_line_length, 1, kMaxLineLengthCap))),
      buf_(max_line_ + 2 + kChunk),
      fd_(fd),
      stop_fd_(stop_fd) {}

LineSource::~LineSource() = default;

// The data ends here, after the last complete line read: a fragment is a line cut by the stop, not data.
void LineSource::Stop() {
  const void* last = end_ > begin_ ? ::memrchr(buf_.data() + begin_, '\n', end_ - begin_) : nullptr;
  end_ = last != nullptr ? static_cast<size_t>(static_cast<const char*>(last) - buf_.data()) + 1 : begin_;
  eof_ = true;
  stopped_ = true;
}

void LineSource::FillFromFd(size_t room) {
  for (;;) {
    if (stop_fd_ >= 0) {
      pollfd fds[2] = {{fd_, POLLIN, 0}, {stop_fd_, POLLIN, 0}};
      if (::poll(fds, 2, -1) < 0) {
        if (errno == EINTR) continue;
        read_errno_ = errno;
        eof_ = true;
        return;
      }
      if (fds[1].revents != 0) return Stop();  // before more data: the stop is for now, not after the backlog
    }
    const ssize_t n = ::read(fd_, buf_.data() + end_, room);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n < 0) read_errno_ = errno;
      eof_ = true;
      return;
    }
    end_ += static_cast<size_t>(n);
    room -= static_cast<size_t>(n);
    if (at_start_ && end_ < 3) continue;  // the first three bytes decide between text, BOM and gzip
    return;
  }
}

void LineSource::Fill() {
  if (begin_ > 0) {
    std::memmove(buf_.data(), buf_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  const size_t room = buf_.size() - end_;  // >= kChunk: callers compact lines shorter than max_line_ + 2
  if (fd_ >= 0) {
    FillFromFd(room);
    if (at_start_) {
      at_start_ = false;
      if (end_ >= 2 && static_cast<unsigned char>(buf_[0]) == 0x1f && static_cast<unsigned char>(buf_[1]) == 0x8b) {
        throw InputError(path_ + ": gzip data; a stream is read as plain text (decompress it first, e.g. zcat)");
      }
      if (end_ >= 3 && std::memcmp(buf_.data(), "\xEF\xBB\xBF", 3) == 0) begin_ = 3;
    }
    return;
  }
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

bool LineSource::Next(TextLine* line) {
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
      line->too_long = length > max_line_;
      line->text = line->too_long ? std::string_view() : std::string_view(start, length);
      return true;
    }
    // pending bytes without a '\n' are already too long even if the next two bytes are "\r\n".
    if (pending > max_line_ + 1) return SkipLongLine(line);
    if (eof_) return false;
    Fill();
  }
}

// Drops the rest of an overlong line chunk by chunk, so memory stays bounded whatever its length.
bool LineSource::SkipLongLine(TextLine* line) {
  uint64_t length = end_ - begin_;
  begin_ = end_ = 0;
  line->number = ++line_no_;
  line->text = {};
  line->too_long = true;
  for (;;) {
    if (eof_) {
      line->terminated = false;
      line->length = length;
      return true;
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
      return true;
    }
    length += pending;
    begin_ = end_ = 0;
  }
}

}  // namespace gins
