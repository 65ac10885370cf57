#include "config/yaml_writer.h"

#include <cmath>
#include <iomanip>
#include <limits>
#include <locale>

namespace gins::config_internal {
namespace {

std::string FixedText(double v, int decimals) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os << std::fixed << std::setprecision(decimals) << v;
  return os.str();
}

std::string Vec3Text(const Vec3& v) {
  return "[" + FormatNumber(v[0]) + ", " + FormatNumber(v[1]) + ", " + FormatNumber(v[2]) + "]";
}

std::string OriginText(const GeodeticPoint& p) {
  return "[" + FormatNumber(p.lat_deg) + ", " + FormatNumber(p.lon_deg) + ", " + FormatNumber(p.alt_m) + "]";
}

}  // namespace

// Keeps the echoed config readable ("0.8", not "0.80000000000000004") and makes the YAML round trip exact.
// Values that came from a config are always reachable (they are to_si of some double near from_si(si));
// others fall back to 17 significant digits, exact to within the conversion's rounding. Plain decimals are
// preferred to exponents ("20", not "2e+01") unless the exponent form is more than 2 characters shorter.
std::string FormatNumber(double si, const Unit& unit) {
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

void YamlWriter::String(const char* key, const std::string& value) {
  std::string quoted = "\"";
  for (const char c : value) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  Put(key, quoted + "\"");
}

void YamlWriter::Put(const char* key, const std::string& value) {
  if (style_ == Style::kFlow) {
    os_ << (first_ ? "" : ", ") << key << ": " << value;
    first_ = false;
  } else {
    os_ << "  " << key << ": " << value << "\n";
  }
}

void YamlWriter::Vector3(const char* key, const Vec3& v, const std::string& /*what*/, const Check& /*check*/) {
  Put(key, Vec3Text(v));
}

// A named mapping when R is exactly one, else the 9 numbers row-major.
void YamlWriter::Axes(const char* key, const Mat3& R) {
  for (const NamedAxes& a : KnownAxes()) {
    if (R == a.R_b_imu) return Put(key, a.name);
  }
  std::string s = "[";
  for (int i = 0; i < 9; ++i) s += (i == 0 ? "" : ", ") + FormatNumber(R(i / 3, i % 3));
  Put(key, s + "]");
}

void YamlWriter::Origin(const char* key, const std::optional<GeodeticPoint>& p) {
  Put(key, p ? OriginText(*p) : "null  # the first usable fix");
}

void YamlWriter::Origin(const char* key, const GeodeticPoint& p) { Put(key, OriginText(p)); }

// [[start, duration], ...] or [].
void YamlWriter::Outages(const char* key, const std::vector<std::pair<double, double>>& outages) {
  std::string text;
  for (const auto& [start, duration] : outages) {
    text += (text.empty() ? "[" : ", ") + std::string("[") + FormatNumber(start) + ", " + FormatNumber(duration) + "]";
  }
  Put(key, text.empty() ? "[]" : text + "]");
}

void YamlWriter::PeriodicOutages(const char* key, const GnssOptions::PeriodicOutages& p) {
  Put(key, p.duration > 0.0 ? "[" + FormatNumber(p.first_start) + ", " + FormatNumber(p.duration) + ", " +
                                  FormatNumber(p.period) + "]"
                            : "[]");
}

}  // namespace gins::config_internal
