#include "core/io/trajectory_writer.h"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "core/io/number_format.h"

namespace gins {
namespace {

// The longest field: a finite double in fixed notation with up to 9 decimals ("-", 309 digits, ".", 9), or in
// scientific notation; and the longest line, the state CSV's 27 fields with their separators.
constexpr size_t kMaxField = 1 + 309 + 1 + 9;
constexpr size_t kMaxFields = 27;

// Builds one output line with the fast formatters of core/number_format.h: printf, then std::to_chars,
// dominated the ESKF's run time at IMU rate. Sized for the longest line of finite values, so no field is ever
// cut (the buffer is not initialised: its size costs nothing).
class Line {
 public:
  Line& Fixed(double v, int precision) {
    pos_ = FormatFixed(pos_, end_, v, precision);
    return *this;
  }
  Line& Sci(double v, int precision) {
    pos_ = FormatScientific(pos_, end_, v, precision);
    return *this;
  }
  Line& Char(char c) {
    if (pos_ < end_) *pos_++ = c;
    return *this;
  }
  void WriteTo(FILE* f) { std::fwrite(buf_, 1, static_cast<size_t>(pos_ - buf_), f); }

 private:
  char buf_[kMaxFields * (kMaxField + 1)];
  char* pos_ = buf_;
  char* end_ = buf_ + sizeof(buf_);
};

}  // namespace

AtomicFile::AtomicFile(const std::string& path)
    : path_(path), tmp_path_(path + ".tmp." + std::to_string(::getpid())) {
  file_ = std::fopen(tmp_path_.c_str(), "wb");
  if (file_ == nullptr) throw std::runtime_error(path_ + ": cannot create: " + std::strerror(errno));
  // Large buffer: trajectory files are written line by line at IMU rate.
  std::setvbuf(file_, nullptr, _IOFBF, 1 << 20);
}

AtomicFile::~AtomicFile() {
  if (file_ != nullptr) std::fclose(file_);
  if (!committed_) std::remove(tmp_path_.c_str());
}

void AtomicFile::Write(const std::string& text) { std::fwrite(text.data(), 1, text.size(), file_); }

void AtomicFile::Commit() {
  if (committed_) return;
  const bool write_error = std::ferror(file_) != 0;
  const int close_result = std::fclose(file_);
  file_ = nullptr;
  if (write_error || close_result != 0) throw std::runtime_error(path_ + ": write failed: " + std::strerror(errno));
  if (std::rename(tmp_path_.c_str(), path_.c_str()) != 0) {
    throw std::runtime_error(path_ + ": cannot rename into place: " + std::strerror(errno));
  }
  committed_ = true;
}

std::string TrajectoryHeader(const std::string& mode, const GeodeticPoint& origin) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), "# gins mode=%s frame=ENU origin_lla=%.10f %.10f %.4f\n", mode.c_str(),
                origin.lat_deg, origin.lon_deg, origin.alt_m);
  return buf;
}

TumWriter::TumWriter(const std::string& path, const std::string& mode, const GeodeticPoint& origin) : file_(path) {
  file_.Write(TrajectoryHeader(mode, origin));
}

const char kStatesCsvColumns[] =
    "t,px,py,pz,vx,vy,vz,qw,qx,qy,qz,bgx,bgy,bgz,bax,bay,baz,"
    "sigma_px,sigma_py,sigma_pz,sigma_vx,sigma_vy,sigma_vz,sigma_att_e,sigma_att_n,sigma_att_u,odom_scale\n";

bool WriteTumLine(FILE* f, const NavState& x) {
  if (!x.AllFinite()) return false;
  Line l;
  l.Fixed(x.t, 6);
  for (int i = 0; i < 3; ++i) l.Char(' ').Fixed(x.p_wb[i], 5);
  l.Char(' ').Fixed(x.q_wb.x(), 9).Char(' ').Fixed(x.q_wb.y(), 9).Char(' ').Fixed(x.q_wb.z(), 9);
  l.Char(' ').Fixed(x.q_wb.w(), 9).Char('\n');
  l.WriteTo(f);
  return true;
}

bool TumWriter::Add(const NavState& x) {
  if (!WriteTumLine(file_.stream(), x)) return false;
  ++count_;
  return true;
}

StatesCsvWriter::StatesCsvWriter(const std::string& path, const std::string& mode, const GeodeticPoint& origin)
    : file_(path) {
  file_.Write(TrajectoryHeader(mode, origin));
  file_.Write(kStatesCsvColumns);
}

bool StatesCsvWriter::Add(const NavState& x, const Vec3& sp, const Vec3& sv, const Vec3& sa, double odom_scale) {
  return WriteStatesCsvLine(file_.stream(), x, sp, sv, sa, odom_scale);
}

bool WriteStatesCsvLine(FILE* f, const NavState& x, const Vec3& sp, const Vec3& sv, const Vec3& sa,
                        double odom_scale) {
  if (!x.AllFinite() || !sp.allFinite() || !sv.allFinite() || !sa.allFinite() || !std::isfinite(odom_scale)) {
    return false;
  }
  Line l;
  l.Fixed(x.t, 6);
  for (int i = 0; i < 3; ++i) l.Char(',').Fixed(x.p_wb[i], 5);
  for (int i = 0; i < 3; ++i) l.Char(',').Fixed(x.v_w[i], 5);
  l.Char(',').Fixed(x.q_wb.w(), 9).Char(',').Fixed(x.q_wb.x(), 9).Char(',').Fixed(x.q_wb.y(), 9);
  l.Char(',').Fixed(x.q_wb.z(), 9);
  for (const Vec3* v : {&x.bg, &x.ba, &sp, &sv, &sa}) {
    for (int i = 0; i < 3; ++i) l.Char(',').Sci((*v)[i], 4);
  }
  l.Char(',').Fixed(odom_scale, 6).Char('\n');
  l.WriteTo(f);
  return true;
}

}  // namespace gins
