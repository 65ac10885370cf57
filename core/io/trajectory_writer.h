// Output files that are complete or absent: everything is written to a temporary name in the target
// directory and renamed into place by Commit(); an uncommitted file is removed.
#pragma once

#include <cstdio>
#include <memory>
#include <string>

#include "core/geodesy.h"
#include "core/nav_state.h"

namespace gins {

// A file written under a temporary name and renamed into place by Commit(): it appears complete or not at
// all. Until then its temporary file is listed process-wide, for AbandonUncommittedFiles.
class AtomicFile {
 public:
  explicit AtomicFile(const std::string& path);  // throws std::runtime_error if it cannot be created
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  FILE* stream() { return file_; }
  void Write(const std::string& text);
  // Flushes, closes and renames into place; throws on any I/O error.
  void Commit();
  const std::string& path() const { return path_; }

 private:
  static constexpr size_t kBufferSize = 1 << 18;  // and at most two copies in flight (background_write.h)
  std::string path_, tmp_path_;
  std::unique_ptr<char[]> buffer_;  // the stream's; outlives it (the destructor closes the stream first)
  FILE* file_ = nullptr;
  bool committed_ = false;
};

// For a process that is about to end on a signal (apps/interrupt.h): removes the temporary file of every
// AtomicFile not yet committed and returns how many; no AtomicFile commits after it (it keeps the list's
// lock). Waits for a CommitGroup that is committing.
size_t AbandonUncommittedFiles();

// Held while a set of files is committed (a run's outputs and its summary): AbandonUncommittedFiles waits
// for it, so an interrupted process leaves all of the set or none.
class CommitGroup {
 public:
  CommitGroup();
  ~CommitGroup();
  CommitGroup(const CommitGroup&) = delete;
  CommitGroup& operator=(const CommitGroup&) = delete;
};

// The TUM file's comment line naming the mode and the world frame's origin (docs/formats.md §5.2).
std::string TrajectoryHeader(const std::string& mode, const GeodeticPoint& origin);

// One line of each format (with its '\n') to any stream: the writers below and `gins stream`'s stdout
// print the same bytes. Nothing is ever written with a number that is not finite: such a state is refused
// whole (false, nothing written), so a NaN cannot reach an output whatever the caller checked. Any finite
// value fits its line, however large.
bool WriteTumLine(FILE* f, const NavState& x);
bool WriteStatesCsvLine(FILE* f, const NavState& x, const Vec3& sigma_p, const Vec3& sigma_v, const Vec3& sigma_att,
                        double odom_scale);
// The states CSV's first line: its column names (the origin is in the TUM file beside it, §5.3).
extern const char kStatesCsvColumns[];
// The geodetic track: one line of "t,lat_deg,lon_deg,height_m,sigma_e_m,sigma_n_m,sigma_u_m" (§5.4), and
// its first line.
bool WriteGeodeticCsvLine(FILE* f, NearGeodetic* geodetic, const NavState& x, const Vec3& sigma_p);
extern const char kGeodeticCsvColumns[];

class StatesCsvWriter;
class GeodeticCsvWriter;

// TUM trajectory: "t x y z qx qy qz qw" (body in w).
class TumWriter {
 public:
  TumWriter(const std::string& path, const std::string& mode, const GeodeticPoint& origin);
  bool Add(const NavState& x);
  // Add(x), states->Add(x, ...) and geodetic->Add(x, sigma_p) in one (either may be null), formatting the
  // fields the lines share (t, p, q, the position σ) once: the same bytes as the separate calls.
  bool AddWithStates(StatesCsvWriter* states, GeodeticCsvWriter* geodetic, const NavState& x, const Vec3& sigma_p,
                     const Vec3& sigma_v, const Vec3& sigma_att, double odom_scale);
  void Commit() { file_.Commit(); }
  uint64_t count() const { return count_; }

 private:
  AtomicFile file_;
  uint64_t count_ = 0;
};

// Full state CSV with 1-σ columns.
class StatesCsvWriter {
 public:
  explicit StatesCsvWriter(const std::string& path);
  bool Add(const NavState& x, const Vec3& sigma_p, const Vec3& sigma_v, const Vec3& sigma_att, double odom_scale);
  void Commit() { file_.Commit(); }
  FILE* stream() { return file_.stream(); }

 private:
  AtomicFile file_;
};

// The geodetic track of a stream: WGS84 latitude, longitude and ellipsoidal height with the position's 1-σ.
class GeodeticCsvWriter {
 public:
  GeodeticCsvWriter(const std::string& path, const LocalEnuFrame& frame);
  bool Add(const NavState& x, const Vec3& sigma_p) { return WriteGeodeticCsvLine(file_.stream(), &geodetic_, x, sigma_p); }
  void Commit() { file_.Commit(); }
  FILE* stream() { return file_.stream(); }
  NearGeodetic* geodetic() { return &geodetic_; }

 private:
  AtomicFile file_;
  NearGeodetic geodetic_;
};

}  // namespace gins
