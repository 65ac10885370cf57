#include "core/io/trajectory_writer.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>

#include "core/io/background_write.h"
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
  // A field formatted before (PoseFields).
  Line& Text(const char* first, const char* last) {
    const size_t n = std::min(static_cast<size_t>(last - first), static_cast<size_t>(end_ - pos_));
    std::memcpy(pos_, first, n);
    pos_ += n;
    return *this;
  }
  void WriteTo(FILE* f) { std::fwrite(buf_, 1, static_cast<size_t>(pos_ - buf_), f); }
  const char* pos() const { return pos_; }

 private:
  char buf_[kMaxFields * (kMaxField + 1)];
  char* pos_ = buf_;
  char* end_ = buf_ + sizeof(buf_);
};

// The temporary files of the AtomicFiles not yet committed. Never destroyed: a signal's thread may use it
// while the process ends. Recursive: a CommitGroup holds it around its files' commits.
std::recursive_mutex& UncommittedLock() {
  static auto* lock = new std::recursive_mutex;
  return *lock;
}
std::set<std::string>& Uncommitted() {
  static auto* files = new std::set<std::string>;
  return *files;
}

}  // namespace

size_t AbandonUncommittedFiles() {
  UncommittedLock().lock();  // not released: the process ends
  for (const std::string& f : Uncommitted()) ::unlink(f.c_str());
  return Uncommitted().size();
}

CommitGroup::CommitGroup() { UncommittedLock().lock(); }
CommitGroup::~CommitGroup() { UncommittedLock().unlock(); }

AtomicFile::AtomicFile(const std::string& path)
    : path_(path), tmp_path_(path + ".tmp." + std::to_string(::getpid())) {
  {
    const std::lock_guard<std::recursive_mutex> lock(UncommittedLock());
    // Large buffer: trajectory files are written line by line at IMU rate. It must be ours: glibc ignores
    // the size when setvbuf allocates (it wrote 4 KiB at a time, one system call per ~15 lines). Its
    // write(2) calls run on a thread of their own (core/io/background_write.h).
    buffer_ = std::make_unique<char[]>(kBufferSize);
    file_ = OpenBackgroundWriteStream(tmp_path_, buffer_.get(), kBufferSize);
    if (file_ == nullptr) throw std::runtime_error(path_ + ": cannot create: " + std::strerror(errno));
    Uncommitted().insert(tmp_path_);
  }
}

AtomicFile::~AtomicFile() {
  if (file_ != nullptr) std::fclose(file_);
  if (committed_) return;
  const std::lock_guard<std::recursive_mutex> lock(UncommittedLock());
  std::remove(tmp_path_.c_str());
  Uncommitted().erase(tmp_path_);
}

void AtomicFile::Write(const std::string& text) { std::fwrite(text.data(), 1, text.size(), file_); }

void AtomicFile::Commit() {
  if (committed_) return;
  const bool write_error = std::ferror(file_) != 0;
  const int close_result = std::fclose(file_);
  file_ = nullptr;
  if (write_error || close_result != 0) throw std::runtime_error(path_ + ": write failed: " + std::strerror(errno));
  // The old file goes first: renaming over it would make ext4 write the new file's data out before the
  // rename returns (its replace-by-rename safeguard, ~0.1 s per hour of IMU-rate output). The new file
  // still appears complete or not at all.
  const std::lock_guard<std::recursive_mutex> lock(UncommittedLock());
  std::remove(path_.c_str());
  if (std::rename(tmp_path_.c_str(), path_.c_str()) != 0) {
    throw std::runtime_error(path_ + ": cannot rename into place: " + std::strerror(errno));
  }
  Uncommitted().erase(tmp_path_);
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

namespace {

// The fields both formats share, formatted once: t, p (x, y, z) and q (x, y, z, w), each [begin[k], end[k]).
class PoseFields {
 public:
  static constexpr int kT = 0, kP = 1, kQ = 4, kFields = 8;
  explicit PoseFields(const NavState& x) {
    const double v[kFields] = {x.t, x.p_wb.x(), x.p_wb.y(), x.p_wb.z(), x.q_wb.x(), x.q_wb.y(), x.q_wb.z(), x.q_wb.w()};
    char* p = buf_;
    for (int k = 0; k < kFields; ++k) {
      begin_[k] = p;
      p = FormatFixed(p, buf_ + sizeof(buf_), v[k], k == kT ? 6 : k < kQ ? 5 : 9);
      end_[k] = p;
    }
  }
  const char* begin(int k) const { return begin_[k]; }
  const char* end(int k) const { return end_[k]; }

 private:
  char buf_[kFields * (kMaxField + 1)];
  const char* begin_[kFields];
  const char* end_[kFields];
};

void WriteTum(FILE* f, const PoseFields& pose) {
  Line l;
  l.Text(pose.begin(PoseFields::kT), pose.end(PoseFields::kT));
  for (int k = PoseFields::kP; k < PoseFields::kFields; ++k) l.Char(' ').Text(pose.begin(k), pose.end(k));
  l.Char('\n').WriteTo(f);
}

bool StatesFinite(const NavState& x, const Vec3& sp, const Vec3& sv, const Vec3& sa, double odom_scale) {
  return x.AllFinite() && sp.allFinite() && sv.allFinite() && sa.allFinite() && std::isfinite(odom_scale);
}

// The [begin, end) of the position σ fields in a states line, for the geodetic line to copy.
struct SigmaFields {
  const char* begin[3];
  const char* end[3];
};

void WriteStatesCsv(FILE* f, const PoseFields& pose, const NavState& x, const Vec3& sp, const Vec3& sv, const Vec3& sa,
                    double odom_scale, Line* l, SigmaFields* sigma) {
  l->Text(pose.begin(PoseFields::kT), pose.end(PoseFields::kT));
  for (int i = 0; i < 3; ++i) l->Char(',').Text(pose.begin(PoseFields::kP + i), pose.end(PoseFields::kP + i));
  for (int i = 0; i < 3; ++i) l->Char(',').Fixed(x.v_w[i], 5);
  // q as w, x, y, z here.
  l->Char(',').Text(pose.begin(PoseFields::kQ + 3), pose.end(PoseFields::kQ + 3));
  for (int i = 0; i < 3; ++i) l->Char(',').Text(pose.begin(PoseFields::kQ + i), pose.end(PoseFields::kQ + i));
  for (const Vec3* v : {&x.bg, &x.ba}) {
    for (int i = 0; i < 3; ++i) l->Char(',').Sci((*v)[i], 4);
  }
  for (int i = 0; i < 3; ++i) {
    l->Char(',');
    sigma->begin[i] = l->pos();
    l->Sci(sp[i], 4);
    sigma->end[i] = l->pos();
  }
  for (const Vec3* v : {&sv, &sa}) {
    for (int i = 0; i < 3; ++i) l->Char(',').Sci((*v)[i], 4);
  }
  l->Char(',').Fixed(odom_scale, 6).Char('\n');
  l->WriteTo(f);
}

// The geodetic line from the fields already formatted: the time and, when a states line was written, its
// position σ (the same formatting: WriteGeodeticCsvLine's bytes).
bool WriteGeodetic(FILE* f, NearGeodetic* geodetic, const PoseFields& pose, const Vec3& p_w, const Vec3& sp,
                   const SigmaFields* sigma) {
  const GeodeticPoint g = (*geodetic)(p_w);
  if (!std::isfinite(g.lat_deg) || !std::isfinite(g.lon_deg) || !std::isfinite(g.alt_m)) return false;
  // 9 decimals of a degree: 0.1 mm, below the TUM file's 5 decimals of a metre.
  Line l;
  l.Text(pose.begin(PoseFields::kT), pose.end(PoseFields::kT));
  l.Char(',').Fixed(g.lat_deg, 9).Char(',').Fixed(g.lon_deg, 9).Char(',').Fixed(g.alt_m, 4);
  for (int i = 0; i < 3; ++i) {
    l.Char(',');
    if (sigma != nullptr) {
      l.Text(sigma->begin[i], sigma->end[i]);
    } else {
      l.Sci(sp[i], 4);
    }
  }
  l.Char('\n').WriteTo(f);
  return true;
}

}  // namespace

bool WriteTumLine(FILE* f, const NavState& x) {
  if (!x.AllFinite()) return false;
  WriteTum(f, PoseFields(x));
  return true;
}

bool TumWriter::Add(const NavState& x) {
  if (!WriteTumLine(file_.stream(), x)) return false;
  ++count_;
  return true;
}

StatesCsvWriter::StatesCsvWriter(const std::string& path) : file_(path) { file_.Write(kStatesCsvColumns); }

const char kGeodeticCsvColumns[] = "t,lat_deg,lon_deg,height_m,sigma_e_m,sigma_n_m,sigma_u_m\n";

bool WriteGeodeticCsvLine(FILE* f, NearGeodetic* geodetic, const NavState& x, const Vec3& sp) {
  if (!x.AllFinite() || !sp.allFinite()) return false;
  return WriteGeodetic(f, geodetic, PoseFields(x), x.p_wb, sp, nullptr);
}

GeodeticCsvWriter::GeodeticCsvWriter(const std::string& path, const LocalEnuFrame& frame)
    : file_(path), geodetic_(frame) {
  file_.Write(kGeodeticCsvColumns);
}

bool StatesCsvWriter::Add(const NavState& x, const Vec3& sp, const Vec3& sv, const Vec3& sa, double odom_scale) {
  return WriteStatesCsvLine(file_.stream(), x, sp, sv, sa, odom_scale);
}

bool WriteStatesCsvLine(FILE* f, const NavState& x, const Vec3& sp, const Vec3& sv, const Vec3& sa,
                        double odom_scale) {
  if (!StatesFinite(x, sp, sv, sa, odom_scale)) return false;
  Line l;
  SigmaFields sigma;
  WriteStatesCsv(f, PoseFields(x), x, sp, sv, sa, odom_scale, &l, &sigma);
  return true;
}

bool TumWriter::AddWithStates(StatesCsvWriter* states, GeodeticCsvWriter* geodetic, const NavState& x,
                              const Vec3& sp, const Vec3& sv, const Vec3& sa, double odom_scale) {
  if (!x.AllFinite()) return false;
  const PoseFields pose(x);
  WriteTum(file_.stream(), pose);
  ++count_;
  Line l;
  SigmaFields sigma;
  const bool states_written = states != nullptr && StatesFinite(x, sp, sv, sa, odom_scale);
  if (states_written) WriteStatesCsv(states->stream(), pose, x, sp, sv, sa, odom_scale, &l, &sigma);
  if (geodetic != nullptr && sp.allFinite()) {
    WriteGeodetic(geodetic->stream(), geodetic->geodetic(), pose, x.p_wb, sp, states_written ? &sigma : nullptr);
  }
  return true;
}

}  // namespace gins
