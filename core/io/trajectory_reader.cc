#include "core/io/trajectory_reader.h"

#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <locale>
#include <map>
#include <sstream>

#include "core/io/log_reader.h"
#include "core/io/number_format.h"

namespace gins {
namespace {

bool IsSeparator(char c) { return c == ',' || c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

// Splits a row at commas and whitespace into [begin, end) ranges of `line`.
void SplitFields(const std::string& line, std::vector<std::pair<size_t, size_t>>* fields) {
  fields->clear();
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && IsSeparator(line[i])) ++i;
    if (i == line.size()) break;
    const size_t begin = i;
    while (i < line.size() && !IsSeparator(line[i])) ++i;
    fields->emplace_back(begin, i);
  }
}

// The whole of [begin, end) is one finite number.
bool ParseFinite(const char* begin, const char* end, double* v) {
  const char* stop = nullptr;
  *v = ParseDouble(begin, end, &stop);
  return stop != begin && stop == end && std::isfinite(*v);
}

// "key=value" from a comment line (value up to the next space).
std::string HeaderValue(const std::string& line, const std::string& key) {
  const size_t at = line.find(key + "=");
  if (at == std::string::npos) return "";
  const size_t begin = at + key.size() + 1;
  const size_t end = line.find_first_of(" \t\r\n", begin);
  return line.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

std::optional<GeodeticPoint> HeaderOrigin(const std::string& line) {
  const size_t at = line.find("origin_lla=");
  if (at == std::string::npos) return std::nullopt;
  std::istringstream in(line.substr(at + 11));
  in.imbue(std::locale::classic());
  GeodeticPoint g;
  if (!(in >> g.lat_deg >> g.lon_deg >> g.alt_m) || !IsPlausibleGeodetic(g.lat_deg, g.lon_deg, g.alt_m)) {
    return std::nullopt;
  }
  return g;
}

// The origin comment of a state CSV's TUM file beside it ("x_states.csv[.gz]" -> "x.tum[.gz]"): our CSVs
// start with their column names, and the run's frame is written once, in the TUM file (docs/formats.md §5.3).
std::optional<GeodeticPoint> SiblingTumOrigin(const std::string& csv_path, std::string* mode) {
  static const std::string kSuffix = "_states.csv";
  const bool gz = csv_path.size() > 3 && csv_path.compare(csv_path.size() - 3, 3, ".gz") == 0;
  const std::string plain = gz ? csv_path.substr(0, csv_path.size() - 3) : csv_path;
  if (plain.size() <= kSuffix.size() || plain.compare(plain.size() - kSuffix.size(), kSuffix.size(), kSuffix) != 0) {
    return std::nullopt;
  }
  const std::string stem = plain.substr(0, plain.size() - kSuffix.size());
  for (const std::string& tum : {stem + ".tum" + (gz ? ".gz" : ""), stem + ".tum"}) {
    gzFile f = gzopen(tum.c_str(), "rb");
    if (f == nullptr) continue;
    char buf[512];
    const bool read = gzgets(f, buf, sizeof(buf)) != nullptr;
    gzclose(f);
    if (!read || buf[0] != '#') continue;
    if (auto origin = HeaderOrigin(buf)) {
      *mode = HeaderValue(buf, "mode");
      return origin;
    }
  }
  return std::nullopt;
}

}  // namespace

void TrajectoryReader::GzClose::operator()(gzFile_s* f) const { gzclose(f); }

TrajectoryReader::TrajectoryReader(const std::string& path) : path_(path), file_(gzopen(path.c_str(), "rb")) {
  if (file_ == nullptr) throw InputError(path + ": cannot open trajectory file");
  has_pending_ = ReadRow(&pending_);
  if (!has_pending_) throw InputError(path + ": no trajectory rows");
  if (!origin_ && header_seen_) origin_ = SiblingTumOrigin(path, &mode_);
}

TrajectoryReader::~TrajectoryReader() = default;

void TrajectoryReader::Fail(const std::string& why) const {
  throw InputError(path_ + ":" + std::to_string(line_no_) + ": " + why);
}

bool TrajectoryReader::Next(TrajectorySample* sample) {
  if (!has_pending_) return false;
  TrajectorySample row;
  while (ReadRow(&row)) {
    if (row.t < pending_.t) Fail("time goes backwards");
    if (row.t == pending_.t) {
      pending_ = row;
      continue;
    }
    *sample = pending_;
    pending_ = row;
    return true;
  }
  *sample = pending_;
  has_pending_ = false;
  return true;
}

bool TrajectoryReader::ReadRow(TrajectorySample* sample) {
  char buf[8192];
  while (gzgets(file_.get(), buf, sizeof(buf)) != nullptr) {
    line_ = buf;
    // A line longer than the buffer arrives in pieces: join them.
    while (!line_.empty() && line_.back() != '\n' && gzgets(file_.get(), buf, sizeof(buf)) != nullptr) line_ += buf;
    ++line_no_;
    const size_t first = line_.find_first_not_of(" \t\r\n");
    if (first == std::string::npos) continue;
    if (line_[first] == '#') {
      if (!origin_) {
        if (auto origin = HeaderOrigin(line_)) {
          origin_ = origin;
          mode_ = HeaderValue(line_, "mode");
        }
      }
      continue;
    }
    SplitFields(line_, &fields_);
    if (fields_.empty()) Fail("expected " + std::to_string(col_.count) + " fields, got 0");  // commas only
    auto parse = [&](size_t i, double* v) {
      return ParseFinite(line_.data() + fields_[i].first, line_.data() + fields_[i].second, v);
    };
    double first_value = 0.0;
    if (!parse(0, &first_value)) {
      // A CSV header row naming the columns.
      auto field = [&](size_t i) { return line_.substr(fields_[i].first, fields_[i].second - fields_[i].first); };
      if (header_seen_ || row_seen_) Fail("expected a row of numbers, got '" + field(0) + "'");
      std::map<std::string, int> index;
      for (size_t i = 0; i < fields_.size(); ++i) index[field(i)] = static_cast<int>(i);
      auto need = [&](const char* name) {
        const auto it = index.find(name);
        if (it == index.end()) Fail(std::string("header lacks column '") + name + "'");
        return it->second;
      };
      col_.t = need("t");
      col_.px = need("px");
      col_.py = need("py");
      col_.pz = need("pz");
      col_.qw = need("qw");
      col_.qx = need("qx");
      col_.qy = need("qy");
      col_.qz = need("qz");
      if (index.count("vx") && index.count("vy") && index.count("vz")) {
        col_.vx = index["vx"];
        col_.vy = index["vy"];
        col_.vz = index["vz"];
        has_velocity_ = true;
      }
      if (index.count("sigma_att_u")) col_.sigma_att_u = index["sigma_att_u"];
      if (index.count("sigma_px") && index.count("sigma_py") && index.count("sigma_pz")) {
        col_.sigma_px = index["sigma_px"];
        col_.sigma_py = index["sigma_py"];
        col_.sigma_pz = index["sigma_pz"];
        has_sigma_ = true;
      }
      col_.count = fields_.size();
      header_seen_ = true;
      continue;
    }
    if (fields_.size() != col_.count) {
      Fail("expected " + std::to_string(col_.count) + " fields, got " + std::to_string(fields_.size()));
    }
    values_.resize(fields_.size());
    for (size_t i = 0; i < fields_.size(); ++i) {
      if (!parse(i, &values_[i])) Fail("field " + std::to_string(i + 1) + " is not a finite number");
    }
    const std::vector<double>& v = values_;
    TrajectorySample s;
    s.t = v[col_.t];
    s.p_w = Vec3(v[col_.px], v[col_.py], v[col_.pz]);
    const Quat q(v[col_.qw], v[col_.qx], v[col_.qy], v[col_.qz]);
    if (q.norm() < 0.5 || q.norm() > 2.0) Fail("quaternion is not a rotation (norm " + std::to_string(q.norm()) + ")");
    s.q_wb = q.normalized();
    if (has_velocity_) s.v_w = Vec3(v[col_.vx], v[col_.vy], v[col_.vz]);
    if (has_sigma_) s.sigma_p = Vec3(v[col_.sigma_px], v[col_.sigma_py], v[col_.sigma_pz]);
    if (col_.sigma_att_u >= 0) s.yaw_known = v[col_.sigma_att_u] < kUnknownYawSigmaBound;
    *sample = s;
    row_seen_ = true;
    return true;
  }
  return false;
}

Trajectory ReadTrajectory(const std::string& path) {
  TrajectoryReader reader(path);
  Trajectory traj;
  traj.path = path;
  TrajectorySample s;
  while (reader.Next(&s)) traj.samples.push_back(s);
  traj.mode = reader.mode();
  traj.origin = reader.origin();
  traj.has_velocity = reader.has_velocity();
  traj.has_sigma = reader.has_sigma();
  return traj;
}

void ChangeFrame(const LocalEnuFrame& from, const LocalEnuFrame& to, Trajectory* trajectory) {
  // p_to = R_to_from · p_from + (from's origin in `to`).
  const Mat3 R_to_from = to.RotationFromLocalEnu(from.origin());
  const Quat q_to_from(R_to_from);
  const Vec3 origin_to = to.ToEnu(from.origin());
  for (TrajectorySample& s : trajectory->samples) {
    s.p_w = R_to_from * s.p_w + origin_to;
    s.q_wb = (q_to_from * s.q_wb).normalized();
    s.v_w = R_to_from * s.v_w;
  }
  trajectory->origin = to.origin();
}

TrajectorySample ToTrajectorySample(const TruthSample& truth) {
  return {truth.t, truth.p_w, truth.q_wb, truth.v_w};
}

std::vector<TrajectorySample> ToTrajectorySamples(const std::vector<TruthSample>& truth) {
  std::vector<TrajectorySample> out;
  out.reserve(truth.size());
  for (const TruthSample& s : truth) out.push_back(ToTrajectorySample(s));
  return out;
}

}  // namespace gins
