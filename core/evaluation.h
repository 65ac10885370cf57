// Accuracy against a truth file (DESIGN §5), computed as the estimate streams in: the estimate is
// interpolated at each truth time it brackets, and the truth is read as the estimate advances, so memory
// holds neither.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/geodesy.h"
#include "core/nav_state.h"

struct gzFile_s;  // zlib's gzFile

namespace gins {

struct TruthSample {
  double t = 0.0;
  Vec3 p_w = Vec3::Zero();
  Quat q_wb = Quat::Identity();
  Vec3 v_w = Vec3::Zero();
};

// Reads t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu (plain or gzip) row by row into the world frame: positions
// through the geodesy, attitude and velocity (given in the local ENU frame at each row's point) rotated
// into w. Memory holds one row. Rows not later than the previous row are dropped. Throws InputError naming
// file and line on malformed rows (when reaching them), and for a file that cannot be opened or has no rows.
class TruthReader {
 public:
  TruthReader(const std::string& path, const LocalEnuFrame& frame);
  ~TruthReader();
  TruthReader(const TruthReader&) = delete;
  TruthReader& operator=(const TruthReader&) = delete;

  // The next sample in strictly increasing time; false at the end.
  bool Next(TruthSample* sample);
  const std::string& path() const { return path_; }

 private:
  struct GzClose {
    void operator()(gzFile_s* f) const;
  };
  std::string path_;
  LocalEnuFrame frame_;
  std::unique_ptr<gzFile_s, GzClose> file_;
  uint64_t line_ = 0;
  bool any_ = false;
  double last_t_ = 0.0;
};

// The whole truth file at once (TruthReader's rows and errors).
std::vector<TruthSample> ReadTruth(const std::string& path, const LocalEnuFrame& frame);

struct AccuracyMetrics {
  uint64_t count = 0;
  double rmse_3d = 0.0, rmse_h = 0.0, rmse_v = 0.0, max_h = 0.0;
  double rmse_vel = 0.0;          // m/s, 3-D
  double rmse_heading_deg = 0.0;  // yaw of the body x axis
  double rmse_att_deg = 0.0;      // full attitude error angle
};

class StreamingEvaluator {
 public:
  // Pulls the truth from `truth` (the next sample in increasing time, false at the end) as the estimates
  // advance, so memory holds one truth sample, e.g. from its own TruthReader.
  explicit StreamingEvaluator(std::function<bool(TruthSample*)> truth);
  // Over truth samples held in memory.
  explicit StreamingEvaluator(std::vector<TruthSample> truth);
  // Estimates must arrive in non-decreasing time.
  void Add(const NavState& x);
  AccuracyMetrics Metrics() const;

 private:
  void Accumulate(const TruthSample& truth, const NavState& est);
  void NextTruth() { have_next_ = truth_(&next_); }
  std::function<bool(TruthSample*)> truth_;
  TruthSample next_;  // the first truth sample not yet passed
  bool have_next_ = false;
  bool have_prev_ = false;
  NavState prev_;
  uint64_t n_ = 0;
  double sum_h2_ = 0.0, sum_v2_ = 0.0, max_h_ = 0.0, sum_vel2_ = 0.0, sum_yaw2_ = 0.0, sum_att2_ = 0.0;
};

}  // namespace gins
