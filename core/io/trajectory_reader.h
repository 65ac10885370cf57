// Reading trajectories back: our TUM files and state CSVs (docs/formats.md §5, plain or gzip), and foreign TUM
// files (evo and others) without an origin. The counterpart of core/io/trajectory_writer.h.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/io/truth_reader.h"
#include "core/geodesy.h"

struct gzFile_s;  // zlib's gzFile

namespace gins {

// One pose (and velocity, when the file has one) in an ENU frame.
struct TrajectorySample {
  double t = 0.0;
  Vec3 p_w = Vec3::Zero();
  Quat q_wb = Quat::Identity();
  Vec3 v_w = Vec3::Zero();
  Vec3 sigma_p = Vec3::Zero();  // m, E N U: a state CSV's sigma_px.. columns (Trajectory::has_sigma)
  // False when a state CSV's sigma_att_u says the estimate has no yaw there (kUnknownYawSigma).
  bool yaw_known = true;
};

struct Trajectory {
  std::string path;
  std::string mode;                     // from the "# gins mode=..." header; empty for foreign files
  std::optional<GeodeticPoint> origin;  // from "origin_lla=lat lon alt"; absent for foreign files
  bool has_velocity = false;            // a state CSV (vx, vy, vz columns)
  bool has_sigma = false;               // a state CSV (sigma_px, sigma_py, sigma_pz columns)
  std::vector<TrajectorySample> samples;  // strictly increasing time
};

// Reads `t x y z qx qy qz qw` (TUM, whitespace separated) or a CSV with a header naming at least
// t,px,py,pz,qw,qx,qy,qz (our *_states.csv; vx,vy,vz give the velocity) row by row: memory holds two rows,
// not the file, so an IMU-rate output of any length reads in constant memory. `#` lines are comments; the
// first one carrying `origin_lla=` gives the origin and `mode=` the name; a state CSV without it (ours start
// with the column names) takes them from the TUM file beside it (x_states.csv -> x.tum), if there is one. Rows with the time of the previous
// row replace it (the later state is the newer estimate), so a sample is handed out once the next time is
// read. Throws InputError naming file and line for unreadable files, malformed or non-finite rows, time
// going backwards, or no rows at all; the constructor already for the first row or an empty file.
class TrajectoryReader {
 public:
  // Reads up to the first row: the header comment (our writers put it on the first line) and the CSV
  // column names are known from here on.
  explicit TrajectoryReader(const std::string& path);
  ~TrajectoryReader();
  TrajectoryReader(const TrajectoryReader&) = delete;
  TrajectoryReader& operator=(const TrajectoryReader&) = delete;

  // The next sample in strictly increasing time; false at the end.
  bool Next(TrajectorySample* sample);

  const std::string& path() const { return path_; }
  // Mode and origin as far as read: a foreign file could carry its origin comment after rows.
  const std::string& mode() const { return mode_; }
  const std::optional<GeodeticPoint>& origin() const { return origin_; }
  bool has_velocity() const { return has_velocity_; }
  bool has_sigma() const { return has_sigma_; }

 private:
  // The next row as read (a repeated time not yet merged); false at the end of the file.
  bool ReadRow(TrajectorySample* sample);
  [[noreturn]] void Fail(const std::string& why) const;

  std::string path_, mode_;
  std::optional<GeodeticPoint> origin_;
  bool has_velocity_ = false, has_sigma_ = false;
  struct GzClose {
    void operator()(gzFile_s* f) const;
  };
  std::unique_ptr<gzFile_s, GzClose> file_;  // closed also when the constructor throws
  uint64_t line_no_ = 0;
  bool header_seen_ = false, row_seen_ = false;
  struct Columns {
    int t = 0, px = 1, py = 2, pz = 3, qx = 4, qy = 5, qz = 6, qw = 7;
    int vx = -1, vy = -1, vz = -1;
    int sigma_att_u = -1;
    int sigma_px = -1, sigma_py = -1, sigma_pz = -1;
    size_t count = 8;
  } col_;
  std::string line_;                               // reused: no allocation per row
  std::vector<std::pair<size_t, size_t>> fields_;  // [begin, end) of each field in line_
  std::vector<double> values_;
  TrajectorySample pending_;  // read, handed out when a later time (or the end) shows it is not replaced
  bool has_pending_ = false;
};

// The whole file at once (TrajectoryReader's formats and errors), for whole-trajectory work such as
// alignment.
Trajectory ReadTrajectory(const std::string& path);

// Re-expresses a trajectory given in `from`'s ENU frame in `to`'s: both are Cartesian frames fixed to the
// Earth, so this is one rotation and one translation (exact, not a small-distance approximation).
void ChangeFrame(const LocalEnuFrame& from, const LocalEnuFrame& to, Trajectory* trajectory);

// Truth samples (core/io/truth_reader.h) as trajectory samples, with velocity.
TrajectorySample ToTrajectorySample(const TruthSample& truth);
std::vector<TrajectorySample> ToTrajectorySamples(const std::vector<TruthSample>& truth);

}  // namespace gins
