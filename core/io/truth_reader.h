// Reader of truth files (docs/formats.md §4): t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu, plain or gzip, row by row into the
// world frame.
#pragma once

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

}  // namespace gins
