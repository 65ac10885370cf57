#include "config/yaml_reader.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <locale>
#include <sstream>

#include "config/config_loader.h"
#include "core/geodesy.h"

namespace gins::config_internal {
namespace {

// ---------------------------------------------------------------------------------------------------------
// Did-you-mean.

size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      const bool same =
          std::tolower(static_cast<unsigned char>(a[i - 1])) == std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (same ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// The known key the user most likely meant, or "" when none is close. A key missing its unit suffix
// ("radius" for "radius_m") is the commonest slip, so a prefix match wins outright.
std::string ClosestKey(const std::string& key, const std::vector<std::string>& known) {
  for (const std::string& k : known) {
    if (k.size() > key.size() + 1 && k.compare(0, key.size(), key) == 0 && k[key.size()] == '_') return k;
  }
  std::string best;
  size_t best_distance = std::max<size_t>(2, key.size() / 3) + 1;
  for (const std::string& k : known) {
    const size_t d = EditDistance(key, k);
    if (d < best_distance) {
      best_distance = d;
      best = k;
    }
  }
  return best;
}

// ---------------------------------------------------------------------------------------------------------
// Scalars.

bool ParseInteger(const std::string& s, long long* v) {
  std::istringstream is(s);
  is.imbue(std::locale::classic());
  is >> *v;
  return !is.fail() && (is >> std::ws).eof();
}

// A quoted scalar is a string in YAML, even if it looks like a number: treat it as one.
bool IsPlainScalar(const YAML::Node& n) { return n.IsScalar() && n.Tag() != "!"; }

bool IsYamlNonFinite(const std::string& s) {
  static const char* const kNames[] = {".inf",  ".Inf",  ".INF", "+.inf",    "+.Inf",    "+.INF", "-.inf",
                                       "-.Inf", "-.INF", ".nan", ".NaN",     ".NAN",     "nan",   "NaN",
                                       "inf",   "-inf",  "+inf", "Infinity", "-Infinity"};
  for (const char* name : kNames) {
    if (s == name) return true;
  }
  return false;
}

std::string Index(size_t i) { return "[" + std::to_string(i) + "]"; }

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// Messages.

std::string OneLine(const std::string& message) {
  std::string out;
  out.reserve(message.size());
  for (const char c : message) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      static const char kHex[] = "0123456789abcdef";
      out += "\\x";
      out.push_back(kHex[u >> 4]);
      out.push_back(kHex[u & 15]);
    } else {
      out.push_back(c);
    }
  }
  return out;
}

std::string Describe(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Null:
      return "nothing (null)";
    case YAML::NodeType::Scalar:
      return "'" + n.Scalar() + "'";
    case YAML::NodeType::Sequence:
      return "a list of " + std::to_string(n.size());
    case YAML::NodeType::Map:
      return "a mapping";
    case YAML::NodeType::Undefined:
      break;
  }
  return "nothing";
}

void Context::Fail(const std::string& path, const std::string& reason, const YAML::Mark& mark) const {
  std::string message = file_ + ": " + path + ": " + reason;
  if (!mark.is_null()) message += " (line " + std::to_string(mark.line + 1) + ")";
  throw ConfigError(OneLine(message));
}

// ---------------------------------------------------------------------------------------------------------
// The mapping and its keys.

YamlReader::YamlReader(const Context& ctx, const YAML::Node& node, std::string path, std::string item_noun)
    : ctx_(ctx), path_(std::move(path)), item_noun_(std::move(item_noun)) {
  if (!node.IsDefined() || node.IsNull()) return;  // an empty section: all defaults
  mark_ = node.Mark();
  if (!node.IsMap()) {
    ctx_.Fail(path_.empty() ? "(top level)" : path_, "expected a mapping of keys, got " + Describe(node), node.Mark());
  }
  for (const auto& kv : node) {
    if (!kv.first.IsScalar()) ctx_.Fail(Path("?"), "keys must be plain names", kv.first.Mark());
    const std::string& key = kv.first.Scalar();
    if (values_.count(key) != 0) ctx_.Fail(Path(key), "duplicate key", kv.first.Mark());
    values_.emplace(key, kv.second);
    order_.emplace_back(key, kv.first.Mark());
  }
}

const YAML::Node* YamlReader::Find(const std::string& key) {
  known_.push_back(key);
  const auto it = values_.find(key);
  return it == values_.end() ? nullptr : &it->second;
}

void YamlReader::Finish() const {
  for (const auto& [key, mark] : order_) {
    if (std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
    for (const RemovedKey& removed : kRemovedKeys) {
      if (Path(key) == removed.path) ctx_.Fail(Path(key), removed.reason, mark);
    }
    std::string reason = "unknown key";
    const std::string guess = ClosestKey(key, known_);
    if (!guess.empty()) reason += " (did you mean " + Path(guess) + "?)";
    ctx_.Fail(Path(key), reason, mark);
  }
}

std::string YamlReader::Join(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& name : names) list += (list.empty() ? "" : ", ") + name;
  return list;
}

// ---------------------------------------------------------------------------------------------------------
// Values.

double YamlReader::ReadNumber(const YAML::Node& n, const std::string& path, const Unit& unit,
                              const Check& check) const {
  double v = 0.0;
  if (!IsPlainScalar(n)) ctx_.Fail(path, "expected a number, got " + Describe(n), n.Mark());
  if (IsYamlNonFinite(n.Scalar())) ctx_.Fail(path, "must be a finite number, got '" + n.Scalar() + "'", n.Mark());
  if (!ParseDouble(n.Scalar(), &v)) ctx_.Fail(path, "expected a number, got " + Describe(n), n.Mark());
  const std::string why = Violation(check, v);
  if (!why.empty()) ctx_.Fail(path, why, n.Mark());
  const double si = unit.to_si(v);
  if (!std::isfinite(si)) ctx_.Fail(path, "out of range (not finite in SI units)", n.Mark());
  return si;
}

long long YamlReader::ReadInteger(const YAML::Node& n, const std::string& path, long long min, long long max) const {
  long long v = 0;
  if (!IsPlainScalar(n) || !ParseInteger(n.Scalar(), &v)) {
    ctx_.Fail(path, "expected an integer, got " + Describe(n), n.Mark());
  }
  const std::string got = " (got " + std::to_string(v) + ")";
  if (v < min) ctx_.Fail(path, "must be >= " + std::to_string(min) + got, n.Mark());
  if (v > max) ctx_.Fail(path, "must be <= " + std::to_string(max) + got, n.Mark());
  return v;
}

Vec3 YamlReader::ReadVec3(const YAML::Node& n, const std::string& path, const std::string& what,
                          const Check& check) const {
  if (!n.IsSequence() || n.size() != 3) {
    ctx_.Fail(path, "expected a list of 3 numbers " + what + ", got " + Describe(n), n.Mark());
  }
  Vec3 v;
  for (int i = 0; i < 3; ++i) v[i] = ReadNumber(n[i], path + Index(i), kNoUnit, check);
  return v;
}

void YamlReader::Number(const char* key, double& out, const Unit& unit, const Check& check, Presence presence) {
  const YAML::Node* n = Find(key);
  if (n == nullptr && presence == Presence::kRequired) {
    ctx_.Fail(Path(key), "missing (every " + item_noun_ + " needs one)", mark_);
  }
  if (n != nullptr) out = ReadNumber(*n, Path(key), unit, check);
}

void YamlReader::NumberOrWord(const char* key, double& out, bool& is_word, const char* word, const Unit& unit,
                              const Check& check) {
  const YAML::Node* n = Find(key);
  if (n == nullptr) return;
  if (IsPlainScalar(*n) && n->Scalar() == word) {
    is_word = true;
    return;
  }
  double v = 0.0;
  if (!IsPlainScalar(*n) || !ParseDouble(n->Scalar(), &v)) {
    ctx_.Fail(Path(key), std::string("expected a number or '") + word + "', got " + Describe(*n), n->Mark());
  }
  out = ReadNumber(*n, Path(key), unit, check);
  is_word = false;
}

void YamlReader::Boolean(const char* key, bool& out) {
  const YAML::Node* n = Find(key);
  if (n == nullptr) return;
  if (!IsPlainScalar(*n) || !YAML::convert<bool>::decode(*n, out)) {
    Fail(key, "expected true or false, got " + Describe(*n), *n);
  }
}

void YamlReader::String(const char* key, std::string& out) {
  const YAML::Node* n = Find(key);
  if (n == nullptr) return;
  if (n->IsNull()) {
    out.clear();
    return;
  }
  if (!n->IsScalar()) Fail(key, "expected a text, got " + Describe(*n), *n);
  out = n->Scalar();
}

int YamlReader::ChoiceIndex(const char* key, const std::vector<std::string>& names) {
  const YAML::Node* n = Find(key);
  if (n == nullptr) return -1;
  if (n->IsScalar()) {
    for (size_t i = 0; i < names.size(); ++i) {
      if (n->Scalar() == names[i]) return static_cast<int>(i);
    }
  }
  std::string reason = "must be one of " + Join(names) + ", got " + Describe(*n);
  if (n->IsScalar()) {
    const std::string guess = ClosestKey(n->Scalar(), names);
    if (!guess.empty()) reason += " (did you mean " + guess + "?)";
  }
  Fail(key, reason, *n);
}

void YamlReader::Vector3(const char* key, Vec3& out, const std::string& what, const Check& check) {
  if (const YAML::Node* n = Find(key)) out = ReadVec3(*n, Path(key), what, check);
}

// ---------------------------------------------------------------------------------------------------------
// Structured values.

void YamlReader::Axes(const char* key, Mat3& out) {
  const YAML::Node* found = Find(key);
  if (found == nullptr) return;
  const YAML::Node& n = *found;
  const std::string path = Path(key);
  const std::string expected = "expected FLU, FRD, RFU or a rotation matrix as 9 numbers (3x3, row-major)";
  if (n.IsScalar()) {
    for (const NamedAxes& a : KnownAxes()) {
      if (n.Scalar() == a.name) {
        out = a.R_b_imu;
        return;
      }
    }
    ctx_.Fail(path, expected + ", got " + Describe(n), n.Mark());
  }
  Mat3 R;
  if (n.IsSequence() && n.size() == 9) {
    for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = ReadNumber(n[i], path + Index(i), kNoUnit, AnyValue());
  } else if (n.IsSequence() && n.size() == 3 && n[0].IsSequence()) {  // also accept [[r00, r01, r02], [...], [...]]
    for (int r = 0; r < 3; ++r) R.row(r) = ReadVec3(n[r], path + Index(r), "(a matrix row)", AnyValue()).transpose();
  } else {
    ctx_.Fail(path, expected + ", got " + Describe(n), n.Mark());
  }
  const double error = (R * R.transpose() - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (error > 1e-6) {
    ctx_.Fail(path, "not an orthonormal matrix (max |R·Rᵀ − I| = " + Text(error, 3) + ", must be <= 1e-6)", n.Mark());
  }
  if (R.determinant() < 0.0) {
    ctx_.Fail(path, "determinant is -1: a reflection, not a rotation (check the sign of one axis)", n.Mark());
  }
  // Matrices typed with ~7 digits are snapped to the nearest rotation; exact ones are kept bit for bit so
  // that the echoed config reproduces them.
  if (error > 1e-12) {
    Eigen::JacobiSVD<Mat3> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    R = svd.matrixU() * svd.matrixV().transpose();
  }
  out = R;
}

std::optional<GeodeticPoint> YamlReader::ReadOrigin(const YAML::Node& n, const std::string& path,
                                                    bool allow_null) const {
  if (allow_null && n.IsNull()) return std::nullopt;
  const std::string what =
      allow_null ? "[lat_deg, lon_deg, alt_m] (or null for the first usable fix)" : "[lat_deg, lon_deg, alt_m]";
  const Vec3 v = ReadVec3(n, path, what, AnyValue());
  if (!IsPlausibleGeodetic(v[0], v[1], v[2])) {
    ctx_.Fail(path, "not a plausible geodetic point (need |lat| <= 90 deg, |lon| <= 180 deg, -1000 m < alt < 100 km)",
              n.Mark());
  }
  return GeodeticPoint{v[0], v[1], v[2]};
}

void YamlReader::Origin(const char* key, std::optional<GeodeticPoint>& out) {
  if (const YAML::Node* n = Find(key)) out = ReadOrigin(*n, Path(key), true);
}

void YamlReader::Origin(const char* key, GeodeticPoint& out) {
  if (const YAML::Node* n = Find(key)) out = *ReadOrigin(*n, Path(key), false);
}

// [[start_s, duration_s], ...]; null = none.
void YamlReader::Outages(const char* key, std::vector<std::pair<double, double>>& out) {
  const YAML::Node* found = Find(key);
  if (found == nullptr) return;
  const YAML::Node& n = *found;
  const std::string path = Path(key);
  std::vector<std::pair<double, double>> outages;
  if (!n.IsNull()) {
    if (!n.IsSequence()) {
      ctx_.Fail(path, "expected a list of [start_s, duration_s] pairs, got " + Describe(n), n.Mark());
    }
    for (size_t i = 0; i < n.size(); ++i) {
      const std::string item_path = path + Index(i);
      if (!n[i].IsSequence() || n[i].size() != 2) {
        ctx_.Fail(item_path, "expected [start_s, duration_s], got " + Describe(n[i]), n[i].Mark());
      }
      const double start = ReadNumber(n[i][0], item_path + "[0]", kNoUnit, NonNegative());
      const double duration = ReadNumber(n[i][1], item_path + "[1]", kNoUnit, Positive());
      outages.emplace_back(start, duration);
    }
  }
  out = std::move(outages);
}

// [first_start_s, duration_s, period_s], or [] / null for none.
void YamlReader::PeriodicOutages(const char* key, GnssOptions::PeriodicOutages& out) {
  const YAML::Node* found = Find(key);
  if (found == nullptr) return;
  const YAML::Node& n = *found;
  const std::string path = Path(key);
  GnssOptions::PeriodicOutages p;
  if (!n.IsNull() && !(n.IsSequence() && n.size() == 0)) {
    const Vec3 v = ReadVec3(n, path, "[first_start_s, duration_s, period_s] (or [] for none)", AnyValue());
    const char* const names[] = {"first_start_s", "duration_s", "period_s"};
    for (int i = 0; i < 3; ++i) {
      const std::string why = Violation(i == 0 ? NonNegative() : Positive(), v[i]);
      if (!why.empty()) ctx_.Fail(path + Index(i) + " (" + names[i] + ")", why, n[i].Mark());
    }
    if (v[1] >= v[2]) {
      ctx_.Fail(path, "duration_s must be shorter than period_s (got " + Text(v[1]) + " >= " + Text(v[2]) + ")",
                n.Mark());
    }
    p.first_start = v[0];
    p.duration = v[1];
    p.period = v[2];
  }
  out = p;
}

}  // namespace gins::config_internal
