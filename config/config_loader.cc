#include "config/config_loader.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <locale>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

namespace gins {
namespace {

// ---------------------------------------------------------------------------------------------------------
// Units. A YAML number is in the unit its key names; to_si converts it. Each to_si performs the operations
// in the same order as the in-class defaults of options.h (e.g. v * kDegToRad / 60.0), so default.yaml loads
// to bit-identical doubles. from_si is only a first guess used when writing (see FormatNumber).

struct Unit {
  double (*to_si)(double);
  double (*from_si)(double);
};

double Same(double v) { return v; }
double DegToRad(double v) { return v * kDegToRad; }
double RadToDeg(double x) { return x * kRadToDeg; }
double DegSqrtHToSi(double v) { return v * kDegToRad / 60.0; }  // deg/√h → rad/s/√Hz
double SiToDegSqrtH(double x) { return x * kRadToDeg * 60.0; }
double PerSqrtHToSi(double v) { return v / 60.0; }  // m/s/√h → m/s²/√Hz; m/s²/√h → m/s²/√s
double SiToPerSqrtH(double x) { return x * 60.0; }
double DegHSqrtHToSi(double v) { return v * kDegToRad / 3600.0 / 60.0; }  // deg/h/√h → rad/s/√s
double SiToDegHSqrtH(double x) { return x * kRadToDeg * 3600.0 * 60.0; }
double DegHToSi(double v) { return v * kDegToRad / 3600.0; }  // deg/h → rad/s
double SiToDegH(double x) { return x * kRadToDeg * 3600.0; }
double CompassToYaw(double v) { return CompassDegToEnuYaw(v); }  // deg clockwise from north → ENU yaw
double YawToCompass(double x) { return EnuYawToCompassDeg(x); }

constexpr Unit kNoUnit{Same, Same};
constexpr Unit kDeg{DegToRad, RadToDeg};
constexpr Unit kDegPerSqrtH{DegSqrtHToSi, SiToDegSqrtH};
constexpr Unit kPerSqrtH{PerSqrtHToSi, SiToPerSqrtH};
constexpr Unit kDegPerHPerSqrtH{DegHSqrtHToSi, SiToDegHSqrtH};
constexpr Unit kDegPerH{DegHToSi, SiToDegH};
constexpr Unit kCompassDeg{CompassToYaw, YawToCompass};

// ---------------------------------------------------------------------------------------------------------
// Range checks, applied to the value in the user's unit (so the message quotes what the user wrote).

struct Check {
  enum class Kind { kAny, kPositive, kNonNegative, kGate, kFraction, kProbability, kWithin };
  Kind kind = Kind::kAny;
  double lo = 0.0;
  double hi = 0.0;
};

constexpr Check AnyValue() { return {}; }
constexpr Check Positive() { return {Check::Kind::kPositive}; }
constexpr Check NonNegative() { return {Check::Kind::kNonNegative}; }
constexpr Check GateProbability() { return {Check::Kind::kGate}; }     // 0 = off, else in (0, 1)
constexpr Check Fraction() { return {Check::Kind::kFraction}; }        // [0, 1]
constexpr Check Probability() { return {Check::Kind::kProbability}; }  // [0, 1)
constexpr Check Within(double lo, double hi) { return {Check::Kind::kWithin, lo, hi}; }

std::string Text(double v, int precision = 6) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os << std::setprecision(precision) << v;
  return os.str();
}

// Empty when v passes, else the reason.
std::string Violation(const Check& c, double v) {
  const std::string got = " (got " + Text(v) + ")";
  switch (c.kind) {
    case Check::Kind::kAny:
      return "";
    case Check::Kind::kPositive:
      return v > 0.0 ? "" : "must be > 0" + got;
    case Check::Kind::kNonNegative:
      return v >= 0.0 ? "" : "must be >= 0" + got;
    case Check::Kind::kGate:
      return v >= 0.0 && v < 1.0 ? "" : "must be in (0, 1), or 0 to disable the gate" + got;
    case Check::Kind::kFraction:
      return v >= 0.0 && v <= 1.0 ? "" : "must be in [0, 1]" + got;
    case Check::Kind::kProbability:
      return v >= 0.0 && v < 1.0 ? "" : "must be in [0, 1)" + got;
    case Check::Kind::kWithin:
      return v >= c.lo && v <= c.hi ? "" : "must be within [" + Text(c.lo) + ", " + Text(c.hi) + "]" + got;
  }
  return "";
}

// ---------------------------------------------------------------------------------------------------------
// Text <-> number, locale-independent (a host program's locale must not turn "0.5" into an error).

bool ParseDouble(const std::string& s, double* v) {
  std::istringstream is(s);
  is.imbue(std::locale::classic());
  is >> *v;
  return !is.fail() && (is >> std::ws).eof() && std::isfinite(*v);
}

bool ParseInteger(const std::string& s, long long* v) {
  std::istringstream is(s);
  is.imbue(std::locale::classic());
  is >> *v;
  return !is.fail() && (is >> std::ws).eof();
}

std::string FixedText(double v, int decimals) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os << std::fixed << std::setprecision(decimals) << v;
  return os.str();
}

// The shortest decimal text whose value, converted by unit.to_si, is exactly `si`: keeps the echoed config
// readable ("0.8", not "0.80000000000000004") and makes the YAML round trip exact. Values that came from a
// config are always reachable (they are to_si of some double near from_si(si)); others fall back to 17
// significant digits, exact to within the conversion's rounding. Plain decimals are preferred to exponents
// ("20", not "2e+01") unless the exponent form is more than 2 characters shorter.
std::string FormatNumber(double si, const Unit& unit = kNoUnit) {
  const double guess = unit.from_si(si);
  if (!std::isfinite(guess)) return Text(guess, 17);
  std::vector<double> candidates = {guess};
  double up = guess, down = guess;
  for (int k = 0; k < 4; ++k) {
    up = std::nextafter(up, std::numeric_limits<double>::infinity());
    down = std::nextafter(down, -std::numeric_limits<double>::infinity());
    candidates.push_back(up);
    candidates.push_back(down);
  }
  const auto exact = [&](const std::string& s) {
    double back = 0.0;
    return ParseDouble(s, &back) && unit.to_si(back) == si;
  };
  std::string best;
  size_t best_score = std::numeric_limits<size_t>::max();
  const auto consider = [&](const std::string& s, size_t penalty) {
    if (s.size() + penalty < best_score && exact(s)) {
      best = s;
      best_score = s.size() + penalty;
    }
  };
  for (double c : candidates) {
    if (std::abs(c) < 1e15) {
      for (int decimals = 0; decimals <= 20; ++decimals) consider(FixedText(c, decimals), 0);
    }
    for (int precision = 1; precision <= 17; ++precision) {
      const std::string s = Text(c, precision);
      consider(s, s.find('e') != std::string::npos ? 3 : 0);
    }
  }
  return best.empty() ? Text(guess, 17) : best;
}

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
// Reading.

// Error messages stay one line whatever the file holds: control bytes (a key with "\n" in it, or yaml-cpp's
// "unknown escape character" quoting the raw character) are written as \xNN. (Found by tests/fuzz.)
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

class Context {
 public:
  explicit Context(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void Fail(const std::string& path, const std::string& reason, const YAML::Mark& mark) const {
    std::string message = file_ + ": " + path + ": " + reason;
    if (!mark.is_null()) message += " (line " + std::to_string(mark.line + 1) + ")";
    throw ConfigError(OneLine(message));
  }

 private:
  std::string file_;
};

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

double ReadNumber(const Context& ctx, const YAML::Node& n, const std::string& path, const Unit& unit,
                  const Check& check) {
  double v = 0.0;
  if (!IsPlainScalar(n)) ctx.Fail(path, "expected a number, got " + Describe(n), n.Mark());
  if (IsYamlNonFinite(n.Scalar())) ctx.Fail(path, "must be a finite number, got '" + n.Scalar() + "'", n.Mark());
  if (!ParseDouble(n.Scalar(), &v)) ctx.Fail(path, "expected a number, got " + Describe(n), n.Mark());
  const std::string why = Violation(check, v);
  if (!why.empty()) ctx.Fail(path, why, n.Mark());
  const double si = unit.to_si(v);
  if (!std::isfinite(si)) ctx.Fail(path, "out of range (not finite in SI units)", n.Mark());
  return si;
}

long long ReadInteger(const Context& ctx, const YAML::Node& n, const std::string& path, long long min, long long max) {
  long long v = 0;
  if (!IsPlainScalar(n) || !ParseInteger(n.Scalar(), &v)) {
    ctx.Fail(path, "expected an integer, got " + Describe(n), n.Mark());
  }
  const std::string got = " (got " + std::to_string(v) + ")";
  if (v < min) ctx.Fail(path, "must be >= " + std::to_string(min) + got, n.Mark());
  if (v > max) ctx.Fail(path, "must be <= " + std::to_string(max) + got, n.Mark());
  return v;
}

// `what` names the elements for messages, e.g. "[x, y, z]".
Vec3 ReadVec3(const Context& ctx, const YAML::Node& n, const std::string& path, const std::string& what,
              const Unit& unit, const Check& check) {
  if (!n.IsSequence() || n.size() != 3) {
    ctx.Fail(path, "expected a list of 3 numbers " + what + ", got " + Describe(n), n.Mark());
  }
  Vec3 v;
  for (int i = 0; i < 3; ++i) {
    v[i] = ReadNumber(ctx, n[i], path + "[" + std::to_string(i) + "]", unit, check);
  }
  return v;
}

// One YAML mapping (a section, or an item of a list of mappings). Keys are looked up by the typed readers,
// which record them as known; Finish() then rejects whatever the file has beyond them.
class MapReader {
 public:
  MapReader(const Context& ctx, const YAML::Node& node, std::string path) : ctx_(ctx), path_(std::move(path)) {
    if (!node.IsDefined() || node.IsNull()) return;  // an empty section: all defaults
    if (!node.IsMap()) {
      ctx_.Fail(path_.empty() ? "(top level)" : path_, "expected a mapping of keys, got " + Describe(node),
                node.Mark());
    }
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) ctx_.Fail(Path("?"), "keys must be plain names", kv.first.Mark());
      const std::string& key = kv.first.Scalar();
      if (values_.count(key) != 0) ctx_.Fail(Path(key), "duplicate key", kv.first.Mark());
      values_.emplace(key, kv.second);
      order_.emplace_back(key, kv.first.Mark());
    }
  }

  std::string Path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const Context& ctx() const { return ctx_; }

  // The value of `key`, or nullptr when the file does not set it. Records `key` as known.
  const YAML::Node* Find(const std::string& key) {
    known_.push_back(key);
    const auto it = values_.find(key);
    return it == values_.end() ? nullptr : &it->second;
  }

  MapReader Section(const std::string& key) {
    const YAML::Node* n = Find(key);
    return MapReader(ctx_, n != nullptr ? *n : YAML::Node(), Path(key));
  }

  void Number(const std::string& key, double* out, const Unit& unit = kNoUnit, const Check& check = AnyValue()) {
    if (const YAML::Node* n = Find(key)) *out = ReadNumber(ctx_, *n, Path(key), unit, check);
  }

  template <typename Int>
  void Integer(const std::string& key, Int* out, long long min, long long max = std::numeric_limits<int>::max()) {
    if (const YAML::Node* n = Find(key)) *out = static_cast<Int>(ReadInteger(ctx_, *n, Path(key), min, max));
  }

  void Boolean(const std::string& key, bool* out) {
    const YAML::Node* n = Find(key);
    if (n == nullptr) return;
    if (!IsPlainScalar(*n) || !YAML::convert<bool>::decode(*n, *out)) {
      ctx_.Fail(Path(key), "expected true or false, got " + Describe(*n), n->Mark());
    }
  }

  // A string out of a fixed set; returns the index into `allowed`.
  void Choice(const std::string& key, const std::vector<std::string>& allowed, int* index) {
    const YAML::Node* n = Find(key);
    if (n == nullptr) return;
    if (n->IsScalar()) {
      for (size_t i = 0; i < allowed.size(); ++i) {
        if (n->Scalar() == allowed[i]) {
          *index = static_cast<int>(i);
          return;
        }
      }
    }
    std::string list;
    for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
    std::string reason = "must be one of " + list + ", got " + Describe(*n);
    if (n->IsScalar()) {
      const std::string guess = ClosestKey(n->Scalar(), allowed);
      if (!guess.empty()) reason += " (did you mean " + guess + "?)";
    }
    ctx_.Fail(Path(key), reason, n->Mark());
  }

  void Vector3(const std::string& key, Vec3* out, const std::string& what, const Unit& unit = kNoUnit,
               const Check& check = AnyValue()) {
    if (const YAML::Node* n = Find(key)) *out = ReadVec3(ctx_, *n, Path(key), what, unit, check);
  }

  // Rejects keys no reader asked for, in file order.
  void Finish() const {
    for (const auto& [key, mark] : order_) {
      if (std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
      std::string reason = "unknown key";
      const std::string guess = ClosestKey(key, known_);
      if (!guess.empty()) reason += " (did you mean " + Path(guess) + "?)";
      ctx_.Fail(Path(key), reason, mark);
    }
  }

 private:
  const Context& ctx_;
  std::string path_;
  std::map<std::string, YAML::Node> values_;
  std::vector<std::pair<std::string, YAML::Mark>> order_;
  std::vector<std::string> known_;
};

// ---------------------------------------------------------------------------------------------------------
// Axis mappings (imu.axes): R_b_imu takes a vector in the logged axes into the body FLU frame.

struct NamedAxes {
  const char* name;
  Mat3 R_b_imu;
};

std::vector<NamedAxes> KnownAxes() {
  Mat3 frd = Vec3(1.0, -1.0, -1.0).asDiagonal();  // forward, right, down: flip y and z
  Mat3 rfu;                                       // right, forward, up: x_b = y_imu, y_b = -x_imu
  rfu << 0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0;
  return {{"FLU", Mat3::Identity()}, {"FRD", frd}, {"RFU", rfu}};
}

Mat3 ReadAxes(const Context& ctx, const YAML::Node& n, const std::string& path) {
  const std::string expected = "expected FLU, FRD, RFU or a rotation matrix as 9 numbers (3x3, row-major)";
  if (n.IsScalar()) {
    for (const NamedAxes& a : KnownAxes()) {
      if (n.Scalar() == a.name) return a.R_b_imu;
    }
    ctx.Fail(path, expected + ", got " + Describe(n), n.Mark());
  }
  Mat3 R;
  if (n.IsSequence() && n.size() == 9) {
    for (int i = 0; i < 9; ++i) {
      R(i / 3, i % 3) = ReadNumber(ctx, n[i], path + "[" + std::to_string(i) + "]", kNoUnit, AnyValue());
    }
  } else if (n.IsSequence() && n.size() == 3 && n[0].IsSequence()) {  // also accept [[r00, r01, r02], [...], [...]]
    for (int r = 0; r < 3; ++r) {
      const std::string row_path = path + "[" + std::to_string(r) + "]";
      R.row(r) = ReadVec3(ctx, n[r], row_path, "(a matrix row)", kNoUnit, AnyValue()).transpose();
    }
  } else {
    ctx.Fail(path, expected + ", got " + Describe(n), n.Mark());
  }
  const double error = (R * R.transpose() - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (error > 1e-6) {
    ctx.Fail(path, "not an orthonormal matrix (max |R·Rᵀ − I| = " + Text(error, 3) + ", must be <= 1e-6)", n.Mark());
  }
  if (R.determinant() < 0.0) {
    ctx.Fail(path, "determinant is -1: a reflection, not a rotation (check the sign of one axis)", n.Mark());
  }
  // Matrices typed with ~7 digits are snapped to the nearest rotation; exact ones are kept bit for bit so
  // that the echoed config reproduces them.
  if (error > 1e-12) {
    Eigen::JacobiSVD<Mat3> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    R = svd.matrixU() * svd.matrixV().transpose();
  }
  return R;
}

std::optional<GeodeticPoint> ReadOrigin(const Context& ctx, const YAML::Node& n, const std::string& path,
                                        bool allow_null) {
  if (allow_null && n.IsNull()) return std::nullopt;
  const std::string what =
      allow_null ? "[lat_deg, lon_deg, alt_m] (or null for the first usable fix)" : "[lat_deg, lon_deg, alt_m]";
  const Vec3 v = ReadVec3(ctx, n, path, what, kNoUnit, AnyValue());
  if (!IsPlausibleGeodetic(v[0], v[1], v[2])) {
    ctx.Fail(path, "not a plausible geodetic point (need |lat| <= 90 deg, |lon| <= 180 deg, -1000 m < alt < 100 km)",
             n.Mark());
  }
  return GeodeticPoint{v[0], v[1], v[2]};
}

// ---------------------------------------------------------------------------------------------------------
// Sections. Key names and units here are the contract documented in config/default.yaml.

void ReadInput(MapReader m, InputOptions* o) {
  int policy = o->on_error == InputErrorPolicy::kSkip ? 0 : 1;
  m.Choice("on_error", {"skip", "stop"}, &policy);
  o->on_error = policy == 0 ? InputErrorPolicy::kSkip : InputErrorPolicy::kStop;
  m.Integer("max_errors", &o->max_errors, 0);
  m.Integer("max_line_length", &o->max_line_length, 1);
  m.Number("max_time_jump_s", &o->max_time_jump, kNoUnit, NonNegative());
  m.Finish();
}

void ReadImu(MapReader m, ImuOptions* o) {
  if (const YAML::Node* n = m.Find("axes")) o->R_b_imu = ReadAxes(m.ctx(), *n, m.Path("axes"));
  m.Number("gyro_noise_deg_sqrt_h", &o->gyro_noise_density, kDegPerSqrtH, Positive());
  m.Number("acc_noise_m_s_sqrt_h", &o->acc_noise_density, kPerSqrtH, Positive());
  m.Number("gyro_bias_rw_deg_h_sqrt_h", &o->gyro_bias_rw, kDegPerHPerSqrtH, Positive());
  m.Number("acc_bias_rw_m_s2_sqrt_h", &o->acc_bias_rw, kPerSqrtH, Positive());
  m.Number("init_gyro_bias_sigma_deg_h", &o->init_gyro_bias_sigma, kDegPerH, Positive());
  m.Number("init_acc_bias_sigma_m_s2", &o->init_acc_bias_sigma, kNoUnit, Positive());
  m.Number("max_gap_s", &o->max_gap, kNoUnit, Positive());
  m.Number("max_gyro_rad_s", &o->max_gyro, kNoUnit, Positive());
  m.Number("max_acc_m_s2", &o->max_acc, kNoUnit, Positive());
  m.Finish();
}

// A lever arm typed in millimetres is the likely mistake behind an arm of more than 100 m.
constexpr Check kLeverCheck = Within(-100.0, 100.0);

// gnss.outages_s uses the same [start_s, duration_s] list as simulate.gnss_outages_s (defined below).
std::vector<std::pair<double, double>> ReadOutages(const Context& ctx, const YAML::Node& n, const std::string& path);

// gnss.periodic_outages_s: [first_start_s, duration_s, period_s], or [] / null for none.
GnssOptions::PeriodicOutages ReadPeriodicOutages(const Context& ctx, const YAML::Node& n, const std::string& path) {
  GnssOptions::PeriodicOutages p;
  if (n.IsNull() || (n.IsSequence() && n.size() == 0)) return p;
  const Vec3 v = ReadVec3(ctx, n, path, "[first_start_s, duration_s, period_s] (or [] for none)", kNoUnit, AnyValue());
  const char* const names[] = {"first_start_s", "duration_s", "period_s"};
  for (int i = 0; i < 3; ++i) {
    const std::string why = Violation(i == 0 ? NonNegative() : Positive(), v[i]);
    if (!why.empty()) ctx.Fail(path + "[" + std::to_string(i) + "] (" + names[i] + ")", why, n[i].Mark());
  }
  if (v[1] >= v[2]) {
    ctx.Fail(path, "duration_s must be shorter than period_s (got " + Text(v[1]) + " >= " + Text(v[2]) + ")",
             n.Mark());
  }
  p.first_start = v[0];
  p.duration = v[1];
  p.period = v[2];
  return p;
}

void ReadGnss(MapReader m, GnssOptions* o) {
  m.Vector3("lever_arm_m", &o->lever_b, "[x, y, z] in the body frame (FLU)", kNoUnit, kLeverCheck);
  m.Number("mount_yaw_deg", &o->mount_yaw, kDeg, Within(-360.0, 360.0));
  m.Vector3("sigma_m", &o->sigma_enu, "[east, north, up]", kNoUnit, Positive());
  m.Number("min_sigma_m", &o->min_sigma, kNoUnit, Positive());
  m.Number("heading_sigma_deg", &o->heading_sigma, kDeg, Positive());
  m.Boolean("use_heading", &o->use_heading);
  m.Number("gate_probability", &o->gate_probability, kNoUnit, GateProbability());
  if (const YAML::Node* n = m.Find("origin")) o->origin = ReadOrigin(m.ctx(), *n, m.Path("origin"), true);
  if (const YAML::Node* n = m.Find("outages_s")) o->outages = ReadOutages(m.ctx(), *n, m.Path("outages_s"));
  if (const YAML::Node* n = m.Find("periodic_outages_s")) {
    o->periodic_outages = ReadPeriodicOutages(m.ctx(), *n, m.Path("periodic_outages_s"));
  }
  m.Finish();
}

void ReadWheel(MapReader m, WheelOptions* o) {
  m.Boolean("enabled", &o->enabled);
  m.Number("radius_m", &o->radius, kNoUnit, Positive());
  m.Number("pulses_per_rev", &o->pulses_per_rev, kNoUnit, Positive());
  m.Number("interval_s", &o->interval, kNoUnit, Positive());
  m.Number("speed_sigma_m_s", &o->speed_sigma, kNoUnit, Positive());
  m.Number("gate_probability", &o->gate_probability, kNoUnit, GateProbability());
  m.Number("scale_sigma", &o->scale_sigma, kNoUnit, Positive());
  m.Number("scale_rw_per_sqrt_s", &o->scale_rw, kNoUnit, Positive());
  m.Boolean("estimate_scale", &o->estimate_scale);
  m.Boolean("nonholonomic", &o->nonholonomic);
  m.Number("nhc_sigma_m_s", &o->nhc_sigma, kNoUnit, Positive());
  m.Finish();
}

void ReadGravity(MapReader m, GravityOptions* o) {
  int model = o->use_normal_gravity ? 0 : 1;
  m.Choice("model", {"normal", "fixed"}, &model);
  o->use_normal_gravity = model == 0;
  // Earth's surface gravity spans 9.76-9.84 m/s²; anything far outside is a typo, not a place.
  m.Number("magnitude_m_s2", &o->magnitude, kNoUnit, Within(9.7, 9.9));
  m.Finish();
}

void ReadInit(MapReader m, InitOptions* o) {
  m.Number("static_duration_s", &o->static_duration, kNoUnit, Positive());
  m.Number("max_gyro_std_deg_s", &o->max_gyro_std, kDeg, Positive());
  m.Number("max_acc_std_m_s2", &o->max_acc_std, kNoUnit, Positive());
  m.Number("max_wait_s", &o->max_wait, kNoUnit, Positive());
  m.Boolean("wait_for_heading", &o->wait_for_heading);
  m.Number("sigma_pos_m", &o->sigma_pos, kNoUnit, Positive());
  m.Number("sigma_vel_m_s", &o->sigma_vel, kNoUnit, Positive());
  m.Number("sigma_roll_pitch_deg", &o->sigma_roll_pitch, kDeg, Positive());
  m.Number("sigma_yaw_deg", &o->sigma_yaw, kDeg, Positive());
  m.Finish();
}

void ReadEskf(MapReader m, EskfOptions* o) {
  m.Boolean("estimate_gravity", &o->estimate_gravity);
  m.Number("gravity_sigma_m_s2", &o->gravity_sigma, kNoUnit, Positive());
  m.Finish();
}

void ReadSmoother(MapReader m, SmootherOptions* o) {
  m.Integer("window_size", &o->window_size, 2);
  m.Number("max_keyframe_interval_s", &o->max_keyframe_interval, kNoUnit, Positive());
  m.Number("min_keyframe_interval_s", &o->min_keyframe_interval, kNoUnit, NonNegative());
  int solver = -1;
  const std::vector<std::string> solvers = {"dense_schur", "sparse_normal_cholesky"};
  m.Choice("linear_solver", solvers, &solver);
  if (solver >= 0) o->linear_solver = solvers[solver];
  m.Integer("max_iterations", &o->max_iterations, 1);
  m.Number("function_tolerance", &o->function_tolerance, kNoUnit, Within(1e-12, 0.1));
  m.Integer("num_threads", &o->num_threads, 1);
  m.Number("gnss_loss_scale", &o->gnss_loss_scale, kNoUnit, Positive());
  m.Number("bias_reintegrate_threshold", &o->bias_reintegrate_threshold, kNoUnit, NonNegative());
  m.Finish();
}

void ReadStandstill(MapReader m, StandstillOptions* o) {
  m.Boolean("enabled", &o->enabled);
  m.Number("window_s", &o->window, kNoUnit, Positive());
  m.Number("max_gyro_std_deg_s", &o->max_gyro_std, kDeg, Positive());
  m.Number("max_acc_std_m_s2", &o->max_acc_std, kNoUnit, Positive());
  m.Number("velocity_sigma_m_s", &o->velocity_sigma, kNoUnit, Positive());
  m.Number("max_speed_m_s", &o->max_speed, kNoUnit, Positive());
  m.Finish();
}

void ReadWatchdog(MapReader m, WatchdogOptions* o) {
  m.Boolean("enabled", &o->enabled);
  m.Number("max_reject_s", &o->max_reject, kNoUnit, Positive());
  m.Number("max_position_sigma_m", &o->max_position_sigma, kNoUnit, Positive());
  m.Finish();
}

std::vector<SimSegment> ReadSegments(const Context& ctx, const YAML::Node& n, const std::string& path) {
  std::vector<SimSegment> segments;
  if (n.IsNull()) return segments;
  if (!n.IsSequence()) {
    ctx.Fail(path, "expected a list of {duration_s, accel_m_s2, yaw_rate_deg_s, grade_deg}, got " + Describe(n),
             n.Mark());
  }
  for (size_t i = 0; i < n.size(); ++i) {
    const std::string item_path = path + "[" + std::to_string(i) + "]";
    if (!n[i].IsMap()) ctx.Fail(item_path, "expected a mapping {duration_s, ...}, got " + Describe(n[i]), n[i].Mark());
    MapReader m(ctx, n[i], item_path);
    SimSegment s;
    if (m.Find("duration_s") == nullptr)
      ctx.Fail(m.Path("duration_s"), "missing (every segment needs one)", n[i].Mark());
    m.Number("duration_s", &s.duration, kNoUnit, Positive());
    m.Number("accel_m_s2", &s.accel, kNoUnit, Within(-10.0, 10.0));
    m.Number("yaw_rate_deg_s", &s.yaw_rate, kDeg, Within(-90.0, 90.0));
    m.Number("grade_deg", &s.grade, kDeg, Within(-45.0, 45.0));
    m.Finish();
    segments.push_back(s);
  }
  return segments;
}

std::vector<std::pair<double, double>> ReadOutages(const Context& ctx, const YAML::Node& n, const std::string& path) {
  std::vector<std::pair<double, double>> outages;
  if (n.IsNull()) return outages;
  const std::string what = "a list of [start_s, duration_s] pairs";
  if (!n.IsSequence()) ctx.Fail(path, "expected " + what + ", got " + Describe(n), n.Mark());
  for (size_t i = 0; i < n.size(); ++i) {
    const std::string item_path = path + "[" + std::to_string(i) + "]";
    if (!n[i].IsSequence() || n[i].size() != 2) {
      ctx.Fail(item_path, "expected [start_s, duration_s], got " + Describe(n[i]), n[i].Mark());
    }
    const double start = ReadNumber(ctx, n[i][0], item_path + "[0]", kNoUnit, NonNegative());
    const double duration = ReadNumber(ctx, n[i][1], item_path + "[1]", kNoUnit, Positive());
    outages.emplace_back(start, duration);
  }
  return outages;
}

void ReadSimulate(MapReader m, SimOptions* o) {
  m.Integer("seed", &o->seed, 0, std::numeric_limits<unsigned>::max());
  m.Number("start_time_s", &o->start_time, kNoUnit, NonNegative());
  if (const YAML::Node* n = m.Find("origin")) o->origin = *ReadOrigin(m.ctx(), *n, m.Path("origin"), false);
  m.Number("initial_heading_deg", &o->initial_yaw, kCompassDeg, Within(-360.0, 360.0));
  if (const YAML::Node* n = m.Find("segments")) o->segments = ReadSegments(m.ctx(), *n, m.Path("segments"));
  m.Integer("repeat", &o->repeat, 1, 100000);
  m.Number("imu_rate_hz", &o->imu_rate, kNoUnit, Positive());
  m.Number("gnss_rate_hz", &o->gnss_rate, kNoUnit, Positive());
  m.Number("wheel_rate_hz", &o->wheel_rate, kNoUnit, Positive());
  // True errors may be zero (a perfect sensor), unlike the estimator's noise models.
  m.Number("gyro_noise_deg_sqrt_h", &o->gyro_noise_density, kDegPerSqrtH, NonNegative());
  m.Number("acc_noise_m_s_sqrt_h", &o->acc_noise_density, kPerSqrtH, NonNegative());
  m.Number("gyro_bias_rw_deg_h_sqrt_h", &o->gyro_bias_rw, kDegPerHPerSqrtH, NonNegative());
  m.Number("acc_bias_rw_m_s2_sqrt_h", &o->acc_bias_rw, kPerSqrtH, NonNegative());
  m.Number("gyro_turn_on_bias_deg_h", &o->gyro_turn_on_bias, kDegPerH, NonNegative());
  m.Number("acc_turn_on_bias_m_s2", &o->acc_turn_on_bias, kNoUnit, NonNegative());
  m.Vector3("gnss_sigma_m", &o->gnss_sigma_enu, "[east, north, up]", kNoUnit, NonNegative());
  m.Boolean("write_gnss_sigma", &o->write_gnss_sigma);
  m.Number("heading_sigma_deg", &o->heading_sigma, kDeg, NonNegative());
  m.Number("heading_invalid_fraction", &o->heading_invalid_fraction, kNoUnit, Fraction());
  if (const YAML::Node* n = m.Find("gnss_outages_s"))
    o->gnss_outages = ReadOutages(m.ctx(), *n, m.Path("gnss_outages_s"));
  m.Number("gnss_outlier_probability", &o->gnss_outlier_probability, kNoUnit, Probability());
  m.Number("gnss_outlier_magnitude_m", &o->gnss_outlier_magnitude, kNoUnit, NonNegative());
  m.Vector3("lever_arm_m", &o->lever_b, "[x, y, z] in the body frame (FLU)", kNoUnit, kLeverCheck);
  m.Number("mount_yaw_deg", &o->mount_yaw, kDeg, Within(-360.0, 360.0));
  m.Number("wheel_radius_m", &o->wheel_radius, kNoUnit, Positive());
  m.Number("pulses_per_rev", &o->pulses_per_rev, kNoUnit, Positive());
  m.Number("wheel_scale", &o->wheel_scale, kNoUnit, Within(0.5, 1.5));
  m.Number("wheel_speed_noise_m_s", &o->wheel_speed_noise, kNoUnit, NonNegative());
  m.Number("track_width_m", &o->track_width, kNoUnit, Positive());
  m.Finish();
}

Options Parse(const Context& ctx, const YAML::Node& root) {
  Options o;
  MapReader top(ctx, root, "");
  ReadInput(top.Section("input"), &o.input);
  ReadImu(top.Section("imu"), &o.imu);
  ReadGnss(top.Section("gnss"), &o.gnss);
  ReadWheel(top.Section("wheel"), &o.wheel);
  ReadGravity(top.Section("gravity"), &o.gravity);
  ReadInit(top.Section("init"), &o.init);
  ReadEskf(top.Section("eskf"), &o.eskf);
  ReadSmoother(top.Section("smoother"), &o.smoother);
  ReadStandstill(top.Section("standstill"), &o.standstill);
  ReadWatchdog(top.Section("watchdog"), &o.watchdog);
  ReadSimulate(top.Section("simulate"), &o.simulate);
  top.Finish();
  return o;
}

// ---------------------------------------------------------------------------------------------------------
// Writing.

std::string Vec3Text(const Vec3& v, const Unit& unit = kNoUnit) {
  return "[" + FormatNumber(v[0], unit) + ", " + FormatNumber(v[1], unit) + ", " + FormatNumber(v[2], unit) + "]";
}

std::string BoolText(bool b) { return b ? "true" : "false"; }

std::string AxesText(const Mat3& R) {
  for (const NamedAxes& a : KnownAxes()) {
    if (R == a.R_b_imu) return a.name;
  }
  std::string s = "[";
  for (int i = 0; i < 9; ++i) s += (i == 0 ? "" : ", ") + FormatNumber(R(i / 3, i % 3));
  return s + "]";
}

std::string OriginText(const GeodeticPoint& p) {
  return "[" + FormatNumber(p.lat_deg) + ", " + FormatNumber(p.lon_deg) + ", " + FormatNumber(p.alt_m) + "]";
}

// [[start, duration], ...] or [].
std::string OutagesText(const std::vector<std::pair<double, double>>& outages) {
  std::string text;
  for (const auto& [start, duration] : outages) {
    text += (text.empty() ? "[" : ", ") + std::string("[") + FormatNumber(start) + ", " + FormatNumber(duration) + "]";
  }
  return text.empty() ? "[]" : text + "]";
}

// Listens to a YAML parser for where documents start (LoadOptionsFromString).
class DocumentStarts : public YAML::EventHandler {
 public:
  std::vector<YAML::Mark> marks;
  void OnDocumentStart(const YAML::Mark& mark) override { marks.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

class YamlWriter {
 public:
  void Section(const std::string& name) { os_ << (os_.tellp() > 0 ? "\n" : "") << name << ":\n"; }
  void Key(const std::string& key, const std::string& value) { os_ << "  " << key << ": " << value << "\n"; }
  void Raw(const std::string& line) { os_ << line << "\n"; }
  std::string str() const { return os_.str(); }

 private:
  std::ostringstream os_;
};

}  // namespace

Options LoadOptionsFromString(const std::string& yaml, const std::string& name_for_errors) {
  const Context ctx(name_for_errors);
  YAML::Node root;
  DocumentStarts starts;
  try {
    // Not YAML::LoadAll: on a stray ',' at the top level (a file that is just ",") yaml-cpp 0.7's parser
    // stops advancing and LoadAll collects empty documents until memory runs out (found by
    // tests/fuzz/config_fuzzer). A listening parser counts at most three document starts instead (two at one
    // position: the parser is stuck), and YAML::Load reads the first document.
    std::istringstream in(yaml);
    YAML::Parser parser(in);
    for (int i = 0; i < 3 && parser.HandleNextDocument(starts); ++i) {
    }
    for (size_t i = 1; i < starts.marks.size(); ++i) {
      const YAML::Mark& m = starts.marks[i];
      if (m.pos == starts.marks[i - 1].pos) {
        throw ConfigError(OneLine(name_for_errors + ": YAML syntax error: unexpected text outside any mapping or " +
                                  "list (line " + std::to_string(m.line + 1) + ", column " +
                                  std::to_string(m.column + 1) + ")"));
      }
    }
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    std::string message = name_for_errors + ": YAML syntax error: " + e.msg;
    if (!e.mark.is_null()) {
      message += " (line " + std::to_string(e.mark.line + 1) + ", column " + std::to_string(e.mark.column + 1) + ")";
    }
    throw ConfigError(OneLine(message));
  }
  // A second document (after `---`) would otherwise be silently ignored.
  if (starts.marks.size() > 1) {
    ctx.Fail("(top level)", "more than one YAML document; put all sections in one", starts.marks[1]);
  }
  try {
    return Parse(ctx, root);
  } catch (const YAML::Exception& e) {
    // Our readers check types before converting, so this is a gap in them; still report it usefully.
    std::string message = name_for_errors + ": " + e.msg;
    if (!e.mark.is_null()) message += " (line " + std::to_string(e.mark.line + 1) + ")";
    throw ConfigError(OneLine(message));
  }
}

Options LoadOptions(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw ConfigError(path + ": is a directory, not a config file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path + ": cannot open: " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw ConfigError(path + ": read error");
  return LoadOptionsFromString(text.str(), path);
}

std::string OptionsToYaml(const Options& o) {
  YamlWriter w;
  w.Raw("# gins effective options (keys, units and meanings: config/default.yaml)");

  w.Section("input");
  w.Key("on_error", o.input.on_error == InputErrorPolicy::kSkip ? "skip" : "stop");
  w.Key("max_errors", std::to_string(o.input.max_errors));
  w.Key("max_line_length", std::to_string(o.input.max_line_length));
  w.Key("max_time_jump_s", FormatNumber(o.input.max_time_jump));

  const ImuOptions& imu = o.imu;
  w.Section("imu");
  w.Key("axes", AxesText(imu.R_b_imu));
  w.Key("gyro_noise_deg_sqrt_h", FormatNumber(imu.gyro_noise_density, kDegPerSqrtH));
  w.Key("acc_noise_m_s_sqrt_h", FormatNumber(imu.acc_noise_density, kPerSqrtH));
  w.Key("gyro_bias_rw_deg_h_sqrt_h", FormatNumber(imu.gyro_bias_rw, kDegPerHPerSqrtH));
  w.Key("acc_bias_rw_m_s2_sqrt_h", FormatNumber(imu.acc_bias_rw, kPerSqrtH));
  w.Key("init_gyro_bias_sigma_deg_h", FormatNumber(imu.init_gyro_bias_sigma, kDegPerH));
  w.Key("init_acc_bias_sigma_m_s2", FormatNumber(imu.init_acc_bias_sigma));
  w.Key("max_gap_s", FormatNumber(imu.max_gap));
  w.Key("max_gyro_rad_s", FormatNumber(imu.max_gyro));
  w.Key("max_acc_m_s2", FormatNumber(imu.max_acc));

  const GnssOptions& gnss = o.gnss;
  w.Section("gnss");
  w.Key("lever_arm_m", Vec3Text(gnss.lever_b));
  w.Key("mount_yaw_deg", FormatNumber(gnss.mount_yaw, kDeg));
  w.Key("sigma_m", Vec3Text(gnss.sigma_enu));
  w.Key("min_sigma_m", FormatNumber(gnss.min_sigma));
  w.Key("heading_sigma_deg", FormatNumber(gnss.heading_sigma, kDeg));
  w.Key("use_heading", BoolText(gnss.use_heading));
  w.Key("gate_probability", FormatNumber(gnss.gate_probability));
  w.Key("origin", gnss.origin ? OriginText(*gnss.origin) : "null  # the first usable fix");
  w.Key("outages_s", OutagesText(gnss.outages));
  const GnssOptions::PeriodicOutages& po = gnss.periodic_outages;
  w.Key("periodic_outages_s", po.duration > 0.0 ? "[" + FormatNumber(po.first_start) + ", " +
                                                      FormatNumber(po.duration) + ", " + FormatNumber(po.period) + "]"
                                                : "[]");

  const WheelOptions& wheel = o.wheel;
  w.Section("wheel");
  w.Key("enabled", BoolText(wheel.enabled));
  w.Key("radius_m", FormatNumber(wheel.radius));
  w.Key("pulses_per_rev", FormatNumber(wheel.pulses_per_rev));
  w.Key("interval_s", FormatNumber(wheel.interval));
  w.Key("speed_sigma_m_s", FormatNumber(wheel.speed_sigma));
  w.Key("gate_probability", FormatNumber(wheel.gate_probability));
  w.Key("scale_sigma", FormatNumber(wheel.scale_sigma));
  w.Key("scale_rw_per_sqrt_s", FormatNumber(wheel.scale_rw));
  w.Key("estimate_scale", BoolText(wheel.estimate_scale));
  w.Key("nonholonomic", BoolText(wheel.nonholonomic));
  w.Key("nhc_sigma_m_s", FormatNumber(wheel.nhc_sigma));

  w.Section("gravity");
  w.Key("model", o.gravity.use_normal_gravity ? "normal" : "fixed");
  w.Key("magnitude_m_s2", FormatNumber(o.gravity.magnitude));

  const InitOptions& init = o.init;
  w.Section("init");
  w.Key("static_duration_s", FormatNumber(init.static_duration));
  w.Key("max_gyro_std_deg_s", FormatNumber(init.max_gyro_std, kDeg));
  w.Key("max_acc_std_m_s2", FormatNumber(init.max_acc_std));
  w.Key("max_wait_s", FormatNumber(init.max_wait));
  w.Key("wait_for_heading", BoolText(init.wait_for_heading));
  w.Key("sigma_pos_m", FormatNumber(init.sigma_pos));
  w.Key("sigma_vel_m_s", FormatNumber(init.sigma_vel));
  w.Key("sigma_roll_pitch_deg", FormatNumber(init.sigma_roll_pitch, kDeg));
  w.Key("sigma_yaw_deg", FormatNumber(init.sigma_yaw, kDeg));

  w.Section("eskf");
  w.Key("estimate_gravity", BoolText(o.eskf.estimate_gravity));
  w.Key("gravity_sigma_m_s2", FormatNumber(o.eskf.gravity_sigma));

  const SmootherOptions& sm = o.smoother;
  w.Section("smoother");
  w.Key("window_size", std::to_string(sm.window_size));
  w.Key("max_keyframe_interval_s", FormatNumber(sm.max_keyframe_interval));
  w.Key("min_keyframe_interval_s", FormatNumber(sm.min_keyframe_interval));
  w.Key("linear_solver", sm.linear_solver);
  w.Key("max_iterations", std::to_string(sm.max_iterations));
  w.Key("function_tolerance", FormatNumber(sm.function_tolerance));
  w.Key("num_threads", std::to_string(sm.num_threads));
  w.Key("gnss_loss_scale", FormatNumber(sm.gnss_loss_scale));
  w.Key("bias_reintegrate_threshold", FormatNumber(sm.bias_reintegrate_threshold));

  const StandstillOptions& st = o.standstill;
  w.Section("standstill");
  w.Key("enabled", BoolText(st.enabled));
  w.Key("window_s", FormatNumber(st.window));
  w.Key("max_gyro_std_deg_s", FormatNumber(st.max_gyro_std, kDeg));
  w.Key("max_acc_std_m_s2", FormatNumber(st.max_acc_std));
  w.Key("velocity_sigma_m_s", FormatNumber(st.velocity_sigma));
  w.Key("max_speed_m_s", FormatNumber(st.max_speed));

  w.Section("watchdog");
  w.Key("enabled", BoolText(o.watchdog.enabled));
  w.Key("max_reject_s", FormatNumber(o.watchdog.max_reject));
  w.Key("max_position_sigma_m", FormatNumber(o.watchdog.max_position_sigma));

  const SimOptions& sim = o.simulate;
  w.Section("simulate");
  w.Key("seed", std::to_string(sim.seed));
  w.Key("start_time_s", FormatNumber(sim.start_time));
  w.Key("origin", OriginText(sim.origin));
  w.Key("initial_heading_deg", FormatNumber(sim.initial_yaw, kCompassDeg));
  if (sim.segments.empty()) {
    w.Key("segments", "[]");
  } else {
    w.Raw("  segments:");
    for (const SimSegment& s : sim.segments) {
      w.Raw("    - {duration_s: " + FormatNumber(s.duration) + ", accel_m_s2: " + FormatNumber(s.accel) +
            ", yaw_rate_deg_s: " + FormatNumber(s.yaw_rate, kDeg) + ", grade_deg: " + FormatNumber(s.grade, kDeg) +
            "}");
    }
  }
  w.Key("repeat", std::to_string(sim.repeat));
  w.Key("imu_rate_hz", FormatNumber(sim.imu_rate));
  w.Key("gnss_rate_hz", FormatNumber(sim.gnss_rate));
  w.Key("wheel_rate_hz", FormatNumber(sim.wheel_rate));
  w.Key("gyro_noise_deg_sqrt_h", FormatNumber(sim.gyro_noise_density, kDegPerSqrtH));
  w.Key("acc_noise_m_s_sqrt_h", FormatNumber(sim.acc_noise_density, kPerSqrtH));
  w.Key("gyro_bias_rw_deg_h_sqrt_h", FormatNumber(sim.gyro_bias_rw, kDegPerHPerSqrtH));
  w.Key("acc_bias_rw_m_s2_sqrt_h", FormatNumber(sim.acc_bias_rw, kPerSqrtH));
  w.Key("gyro_turn_on_bias_deg_h", FormatNumber(sim.gyro_turn_on_bias, kDegPerH));
  w.Key("acc_turn_on_bias_m_s2", FormatNumber(sim.acc_turn_on_bias));
  w.Key("gnss_sigma_m", Vec3Text(sim.gnss_sigma_enu));
  w.Key("write_gnss_sigma", BoolText(sim.write_gnss_sigma));
  w.Key("heading_sigma_deg", FormatNumber(sim.heading_sigma, kDeg));
  w.Key("heading_invalid_fraction", FormatNumber(sim.heading_invalid_fraction));
  w.Key("gnss_outages_s", OutagesText(sim.gnss_outages));
  w.Key("gnss_outlier_probability", FormatNumber(sim.gnss_outlier_probability));
  w.Key("gnss_outlier_magnitude_m", FormatNumber(sim.gnss_outlier_magnitude));
  w.Key("lever_arm_m", Vec3Text(sim.lever_b));
  w.Key("mount_yaw_deg", FormatNumber(sim.mount_yaw, kDeg));
  w.Key("wheel_radius_m", FormatNumber(sim.wheel_radius));
  w.Key("pulses_per_rev", FormatNumber(sim.pulses_per_rev));
  w.Key("wheel_scale", FormatNumber(sim.wheel_scale));
  w.Key("wheel_speed_noise_m_s", FormatNumber(sim.wheel_speed_noise));
  w.Key("track_width_m", FormatNumber(sim.track_width));
  return w.str();
}

}  // namespace gins
