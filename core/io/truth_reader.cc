#include "core/io/truth_reader.h"

#include <zlib.h>

#include <cmath>
#include <cstring>

#include "core/io/log_reader.h"
#include "core/io/number_format.h"

namespace gins {

void TruthReader::GzClose::operator()(gzFile_s* f) const { gzclose(f); }

TruthReader::TruthReader(const std::string& path, const LocalEnuFrame& frame)
    : path_(path), frame_(frame), file_(gzopen(path.c_str(), "rb")) {
  if (file_ == nullptr) throw InputError(path + ": cannot open truth file");
}

TruthReader::~TruthReader() = default;

bool TruthReader::Next(TruthSample* sample) {
  char buf[4096];
  while (gzgets(file_.get(), buf, sizeof(buf)) != nullptr) {
    ++line_;
    if (buf[0] == '#' || buf[0] == '\n' || buf[0] == '\r' || buf[0] == 't') continue;  // comments, header
    double v[11];
    const char* p = buf;
    const char* const line_end = buf + std::strlen(buf);
    for (int i = 0; i < 11; ++i) {
      const char* end = nullptr;
      v[i] = ParseDouble(p, line_end, &end);
      if (end == p || !std::isfinite(v[i])) {
        throw InputError(path_ + ":" + std::to_string(line_) + ": truth row needs 11 numeric fields");
      }
      p = end;
      while (*p == ',' || *p == ' ') ++p;
    }
    while (*p == '\r' || *p == '\n' || *p == ' ') ++p;
    if (*p != '\0') throw InputError(path_ + ":" + std::to_string(line_) + ": truth row has more than 11 fields");
    if (!IsPlausibleGeodetic(v[1], v[2], v[3])) {
      throw InputError(path_ + ":" + std::to_string(line_) + ": truth row's latitude, longitude or height out of range");
    }
    const double q_norm = Quat(v[4], v[5], v[6], v[7]).norm();
    if (q_norm < 0.5 || q_norm > 2.0) {
      throw InputError(path_ + ":" + std::to_string(line_) + ": truth row's quaternion is not a rotation (norm " +
                       std::to_string(q_norm) + ")");
    }
    if (any_ && v[0] <= last_t_) continue;
    TruthSample s;
    s.t = v[0];
    const GeodeticPoint g{v[1], v[2], v[3]};
    s.p_w = frame_.ToEnu(g);
    // The file's attitude and velocity are in the local ENU frame at the row's point; w is the tangent
    // frame at the origin, turned against it by the meridian convergence and the Earth's curvature.
    const Mat3 R_w_l = frame_.RotationFromLocalEnu(g);
    s.q_wb = (Quat(R_w_l) * Quat(v[4], v[5], v[6], v[7]).normalized()).normalized();
    s.v_w = R_w_l * Vec3(v[8], v[9], v[10]);
    *sample = s;
    any_ = true;
    last_t_ = s.t;
    return true;
  }
  if (!any_) throw InputError(path_ + ": no truth rows");
  return false;
}

std::vector<TruthSample> ReadTruth(const std::string& path, const LocalEnuFrame& frame) {
  TruthReader reader(path, frame);
  std::vector<TruthSample> out;
  TruthSample s;
  while (reader.Next(&s)) out.push_back(s);
  return out;
}

}  // namespace gins
