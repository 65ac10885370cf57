#include "core/io/log_writer.h"

#include <zlib.h>

#include <charconv>
#include <cstdio>
#include <stdexcept>
#include <variant>
#include <vector>

namespace gins {
namespace {

// Text is handed to the file (or to zlib) in pieces of about this size.
constexpr size_t kBufferSize = 256 * 1024;

bool EndsWith(const std::string& s, const char* suffix) {
  const std::string_view x(suffix);
  return s.size() >= x.size() && s.compare(s.size() - x.size(), x.size(), x) == 0;
}

// " <v>" in the shortest form that reads back to the same double.
void AppendNumber(std::string* out, double v) {
  char buf[32];
  buf[0] = ' ';
  const std::to_chars_result r = std::to_chars(buf + 1, buf + sizeof(buf), v);
  out->append(buf, r.ptr);
}

// A record's fields after its time stamp.
void AppendFields(std::string* out, const ImuSample& s) {
  for (int i = 0; i < 3; ++i) AppendNumber(out, s.gyro[i]);
  for (int i = 0; i < 3; ++i) AppendNumber(out, s.acc[i]);
}

void AppendFields(std::string* out, const WheelRecord& o) {
  AppendNumber(out, o.left_pulses);
  AppendNumber(out, o.right_pulses);
}

void AppendFields(std::string* out, const GnssRecord& g) {
  AppendNumber(out, g.lat_deg);
  AppendNumber(out, g.lon_deg);
  AppendNumber(out, g.alt_m);
  AppendNumber(out, g.heading_valid ? g.heading_deg : 0.0);
  *out += g.heading_valid ? " 1" : " 0";
  if (g.has_sigma) {
    for (int i = 0; i < 3; ++i) AppendNumber(out, g.sigma_enu[i]);
  }
}

void AppendFields(std::string* out, const GnssVelocityRecord& v) {
  for (int i = 0; i < 3; ++i) AppendNumber(out, v.v_enu[i]);
  if (v.has_sigma) {
    for (int i = 0; i < 3; ++i) AppendNumber(out, v.sigma_enu[i]);
  }
}

// A measurement module's record: its numbers after the time (core/measurement_module.h).
template <typename R>
void AppendFields(std::string* out, const R& r) {
  double v[RecordTraits<R>::kInfo.max_fields];
  const size_t n = R::Values(r, v);
  for (size_t i = 1; i < n; ++i) AppendNumber(out, v[i]);
}

}  // namespace

// A gzip stream deflated into the AtomicFile's stdio stream, in bounded memory.
class LogWriter::Gzip {
 public:
  explicit Gzip(const std::string& path) : path_(path), out_(kBufferSize) {
    // windowBits 15 + 16: a gzip wrapper (what LogReader's gzread expects), not a raw zlib stream.
    if (deflateInit2(&z_, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
      throw std::runtime_error(path_ + ": cannot start gzip compression");
    }
  }
  ~Gzip() { deflateEnd(&z_); }
  Gzip(const Gzip&) = delete;
  Gzip& operator=(const Gzip&) = delete;

  void Write(std::string_view text, bool finish, FILE* f) {
    z_.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
    z_.avail_in = static_cast<uInt>(text.size());
    const int flush = finish ? Z_FINISH : Z_NO_FLUSH;
    int status = Z_OK;
    do {
      z_.next_out = out_.data();
      z_.avail_out = static_cast<uInt>(out_.size());
      status = deflate(&z_, flush);
      if (status == Z_STREAM_ERROR) throw std::runtime_error(path_ + ": gzip compression failed");
      std::fwrite(out_.data(), 1, out_.size() - z_.avail_out, f);
    } while (z_.avail_out == 0 || (finish && status != Z_STREAM_END));
  }

 private:
  const std::string path_;
  z_stream z_{};
  std::vector<Bytef> out_;
};

LogWriter::LogWriter(const std::string& path) : file_(path) {
  if (EndsWith(path, ".gz")) gzip_ = std::make_unique<Gzip>(path);
  buf_.reserve(kBufferSize + 512);
}

LogWriter::~LogWriter() = default;

void LogWriter::Flush() {
  if (gzip_) {
    gzip_->Write(buf_, false, file_.stream());
  } else {
    std::fwrite(buf_.data(), 1, buf_.size(), file_.stream());
  }
  buf_.clear();
}

void LogWriter::Put(std::string_view text) {
  buf_.append(text);
  if (buf_.size() >= kBufferSize) Flush();
}

void LogWriter::Comment(std::string_view text) {
  std::string line = "# ";
  for (const char c : text) line.push_back(c == '\n' || c == '\r' ? ' ' : c);
  line.push_back('\n');
  Put(line);
}

template <typename R>
void LogWriter::Write(const R& m) {
  buf_ += RecordTraits<R>::kInfo.token;
  AppendNumber(&buf_, m.t);
  AppendFields(&buf_, m);
  Put("\n");
  ++records_;
}

void LogWriter::Add(const LogRecord& r) {
  std::visit([this](const auto& m) { Write(m); }, r.data);
}

void LogWriter::Commit() {
  if (gzip_) {
    gzip_->Write(buf_, true, file_.stream());
    buf_.clear();
  } else {
    Flush();
  }
  file_.Commit();
}

}  // namespace gins
