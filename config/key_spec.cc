#include "config/key_spec.h"

#include <cmath>
#include <iomanip>
#include <locale>
#include <sstream>

namespace gins::config_internal {

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

std::vector<NamedAxes> KnownAxes() {
  Mat3 frd = Vec3(1.0, -1.0, -1.0).asDiagonal();  // forward, right, down: flip y and z
  Mat3 rfu;                                       // right, forward, up: x_b = y_imu, y_b = -x_imu
  rfu << 0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0;
  return {{"FLU", Mat3::Identity()}, {"FRD", frd}, {"RFU", rfu}};
}

std::string Text(double v, int precision) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os << std::setprecision(precision) << v;
  return os.str();
}

bool ParseDouble(const std::string& s, double* v) {
  std::istringstream is(s);
  is.imbue(std::locale::classic());
  is >> *v;
  return !is.fail() && (is >> std::ws).eof() && std::isfinite(*v);
}

}  // namespace gins::config_internal
