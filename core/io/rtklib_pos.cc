// RTKLIB solution files (core/io/gnss_formats.h): the layout as RTKLIB's outsolhead writes it (RTKLIB
// 2.4.3 src/solution.c; manual App. B.5), found from the "%" column line, read line by line.
#include <GeographicLib/Geocentric.hpp>
#include <cmath>
#include <deque>
#include <map>
#include <vector>

#include "core/io/gnss_formats.h"

namespace gins {
namespace {

using gnss_reason::kBadTime;
using gnss_reason::kTimeBackwards;
using gnss_reason::kUnknownQuality;
using input_reason::kBadNumber;
using input_reason::kDuplicate;
using input_reason::kMissingFields;
using input_reason::kNonFinite;

// RTKLIB prints σ with 4 decimals: a 0.0000 is below that, not zero (a zero σ would break a solver).
constexpr double kMinSigma = 1e-4;
constexpr int64_t kJstMinusUtc = 9 * 3600;

// RTKLIB's Q: 1 fix, 2 float, 3 sbas, 4 dgps, 5 single, 6 ppp (rtklib.h SOLQ_*).
constexpr FixQuality kPosQuality[] = {FixQuality::kFix,  FixQuality::kFloat,  FixQuality::kSbas,
                                      FixQuality::kDgps, FixQuality::kSingle, FixQuality::kPpp};

enum class Position { kDegrees, kDms, kEcef };

// Token index of each column of a data line (-1: absent). The time takes tokens 0 and 1 in either form.
struct Layout {
  bool known = false;
  TimeSystem system = TimeSystem::kGpst;
  bool jst = false;
  Position position = Position::kDegrees;
  int pos = 2, q = -1;
  int sd[6] = {-1, -1, -1, -1, -1, -1};   // sdn sde sdu sdne sdeu sdun | sdx sdy sdz sdxy sdyz sdzx
  int vel[3] = {-1, -1, -1};              // ve vn vu | vx vy vz
  int sdv[6] = {-1, -1, -1, -1, -1, -1};  // sdve sdvn sdvu | sdvx .. sdvzx (only the first three for ENU)
  int tokens = 0;                         // tokens a line needs
};

int Find(const std::map<std::string, int>& columns, const char* name) {
  const auto it = columns.find(name);
  return it == columns.end() ? -1 : it->second;
}

// The layout from the column names of RTKLIB's header line ("%  GPST  latitude(deg) ...").
Layout FromColumns(const std::vector<std::string_view>& names, TimeSystem system, bool jst) {
  std::map<std::string, int> at;
  int index = 2;
  for (size_t k = 1; k < names.size(); ++k) {  // names[0] is the time's
    const std::string name(names[k]);
    at[name] = index;
    index += name.find("(d'") != std::string::npos ? 3 : 1;  // d m s take three tokens
  }
  Layout l;
  l.known = true;
  l.system = system;
  l.jst = jst;
  const bool ecef = at.count("x-ecef(m)") != 0;
  l.position = ecef ? Position::kEcef : at.count("latitude(d'\")") != 0 ? Position::kDms : Position::kDegrees;
  l.pos = ecef ? Find(at, "x-ecef(m)") : std::max(Find(at, "latitude(deg)"), Find(at, "latitude(d'\")"));
  l.q = Find(at, "Q");
  const char* sd_enu[] = {"sdn(m)", "sde(m)", "sdu(m)", "sdne(m)", "sdeu(m)", "sdun(m)"};
  const char* sd_xyz[] = {"sdx(m)", "sdy(m)", "sdz(m)", "sdxy(m)", "sdyz(m)", "sdzx(m)"};
  const char* v_enu[] = {"ve(m/s)", "vn(m/s)", "vu(m/s)"};
  const char* v_xyz[] = {"vx(m/s)", "vy(m/s)", "vz(m/s)"};
  const char* sdv_enu[] = {"sdve", "sdvn", "sdvu", "", "", ""};
  const char* sdv_xyz[] = {"sdvx", "sdvy", "sdvz", "sdvxy", "sdvyz", "sdvzx"};
  for (int i = 0; i < 6; ++i) {
    l.sd[i] = Find(at, ecef ? sd_xyz[i] : sd_enu[i]);
    l.sdv[i] = Find(at, ecef ? sdv_xyz[i] : sdv_enu[i]);
  }
  if (!ecef && l.sd[5] < 0) l.sd[5] = Find(at, "sdue(m)");  // RTKLIB's name for sdun in the d m s header
  for (int i = 0; i < 3; ++i) l.vel[i] = Find(at, ecef ? v_xyz[i] : v_enu[i]);
  l.tokens = index;
  return l;
}

// RTKLIB's default layout (lat/lon/height in degrees, Q, ns, six σ, age, ratio) for a file without its header.
Layout DefaultLayout(bool ecef) {
  Layout l;
  l.known = true;
  l.position = ecef ? Position::kEcef : Position::kDegrees;
  l.q = 5;
  for (int i = 0; i < 6; ++i) l.sd[i] = 7 + i;
  l.tokens = 13;
  return l;
}

// A symmetric covariance from RTKLIB's signed square roots (sdxy = sign(c)·√|c|).
Mat3 Covariance(const double sd[6]) {
  auto c = [](double v) { return v * std::abs(v); };
  Mat3 cov;
  cov << c(sd[0]), c(sd[3]), c(sd[5]), c(sd[3]), c(sd[1]), c(sd[4]), c(sd[5]), c(sd[4]), c(sd[2]);
  return cov;
}

Vec3 Floored(double e, double n, double u) {
  return Vec3(std::max(e, kMinSigma), std::max(n, kMinSigma), std::max(u, kMinSigma));
}

Vec3 SigmaOf(const Mat3& cov_enu) {
  return Floored(std::sqrt(std::max(cov_enu(0, 0), 0.0)), std::sqrt(std::max(cov_enu(1, 1), 0.0)),
                 std::sqrt(std::max(cov_enu(2, 2), 0.0)));
}

class RtklibPosReader : public RecordSource {
 public:
  RtklibPosReader(const std::string& path, const InputOptions& options, const GnssFormatOptions& format)
      : RecordSource(path), format_(format), lines_(&file_, options) {}
  bool Next(LogRecord* record) override;

 private:
  void Header(const TextLine& line);
  void Infer(const TextLine& line);
  // nullptr when the line converted (or was dropped), else the damage reason with *detail.
  const char* Convert(const TextLine& line, std::string* detail);
  const char* Number(int index, const char* name, double* v, std::string* detail) const;
  const char* ReadPosition(double* lat, double* lon, double* h, Mat3* R_ecef_enu, std::string* detail) const;
  const char* ReadSigma(const int (&columns)[6], double sd[6], std::string* detail) const;
  void Describe();

  const GnssFormatOptions format_;
  InputLines lines_;
  Layout layout_;
  std::vector<std::string_view> fields_;
  std::deque<LogRecord> pending_;
  bool have_last_ = false;
  double last_t_ = 0.0;
};

bool RtklibPosReader::Next(LogRecord* record) {
  while (pending_.empty()) {
    TextLine line;
    if (!lines_.Next(&line)) return false;
    SplitFields(line.text, FieldSplit::kWhitespace, ' ', &fields_);
    if (fields_.empty()) continue;
    if (fields_[0][0] == '%' || fields_[0][0] == '#') {
      Header(line);
      continue;
    }
    if (!layout_.known) Infer(line);
    std::string detail;
    if (const char* reason = Convert(line, &detail)) lines_.Damage(line, reason, detail);
  }
  *record = pending_.front();
  pending_.pop_front();
  return true;
}

void RtklibPosReader::Header(const TextLine& line) {
  const std::string_view text = line.text;
  if (text.find("height=WGS84/geodetic") != std::string_view::npos) {
    lines_.issues().Refuse(line.number,
                           "heights above the geoid (RTKLIB out-height=geodetic): gins needs "
                           "ellipsoidal heights; rerun with out-height=ellipsoidal (the default)");
  }
  if (text.find("-baseline(m)") != std::string_view::npos) {
    lines_.issues().Refuse(line.number, "e/n/u baselines (rnx2rtkp -a): not positions; rerun without -a");
  }
  const size_t start = text.find_first_not_of("%# \t");
  if (start == std::string_view::npos || layout_.known) return;
  std::vector<std::string_view> names;
  SplitFields(text.substr(start), FieldSplit::kWhitespace, ' ', &names);
  const std::string_view time = names[0];
  if (time != "GPST" && time != "UTC" && time != "JST") return;
  layout_ = FromColumns(names, time == "GPST" ? TimeSystem::kGpst : TimeSystem::kUtc, time == "JST");
  if (layout_.pos < 0 || layout_.q < 0) {
    lines_.issues().Refuse(line.number,
                           "RTKLIB column line without latitude(deg), latitude(d'\") or x-ecef(m), "
                           "or without Q: " +
                               QuoteToken(text));
  }
  Describe();
}

// No header: RTKLIB's default columns, GPST times; ECEF when the first position is metres from the centre.
void RtklibPosReader::Infer(const TextLine& line) {
  double v[3] = {0, 0, 0};
  bool numbers = fields_.size() >= 5;
  for (int i = 0; i < 3 && numbers; ++i) numbers = ParseNumber(fields_[2 + i], &v[i]) == NumberStatus::kOk;
  const bool ecef = numbers && std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) > 1e6;
  layout_ = DefaultLayout(ecef);
  lines_.issues().Warn(line.number, "no_header",
                       std::string("no RTKLIB column line before the first solution: taken as GPST, ") +
                           (ecef ? "x/y/z-ecef" : "latitude/longitude/height (deg)") + ", Q, ns, sdn..sdun");
  Describe();
}

void RtklibPosReader::Describe() {
  const Layout& l = layout_;
  stats_.time_system = l.system == TimeSystem::kGpst ? "GPST" : "UTC";
  stats_.description =
      std::string("RTKLIB solution, ") +
      (l.jst                           ? "JST"
       : l.system == TimeSystem::kGpst ? "GPST"
                                       : "UTC") +
      ", " + (l.position == Position::kEcef ? "x/y/z-ecef" : "lat/lon/height") +
      (l.sd[0] >= 0 ? (l.position == Position::kEcef ? ", σ sdx..sdzx into ENU" : ", σ sdn sde sdu") : ", no σ") +
      (l.vel[0] >= 0 ? ", velocity as GVEL" : "");
}

const char* RtklibPosReader::Number(int index, const char* name, double* v, std::string* detail) const {
  const NumberStatus status = ParseNumber(fields_[index], v);
  if (status == NumberStatus::kOk) return nullptr;
  *detail = FormatText("column %d (%s) %s is %s", index + 1, name, QuoteToken(fields_[index]).c_str(),
                       status == NumberStatus::kBad ? "not a number" : "not finite");
  return status == NumberStatus::kBad ? kBadNumber : kNonFinite;
}

const char* RtklibPosReader::ReadPosition(double* lat, double* lon, double* h, Mat3* R_ecef_enu,
                                          std::string* detail) const {
  const int p = layout_.pos;
  if (layout_.position == Position::kDegrees) {
    const char* reason = Number(p, "latitude", lat, detail);
    if (reason == nullptr) reason = Number(p + 1, "longitude", lon, detail);
    if (reason == nullptr) reason = Number(p + 2, "height", h, detail);
    return reason;
  }
  if (layout_.position == Position::kDms) {
    double* out[2] = {lat, lon};
    const char* names[2] = {"latitude", "longitude"};
    for (int k = 0; k < 2; ++k) {
      double d = 0, m = 0, s = 0;
      const int i = p + 3 * k;
      const char* reason = Number(i, names[k], &d, detail);
      if (reason == nullptr) reason = Number(i + 1, names[k], &m, detail);
      if (reason == nullptr) reason = Number(i + 2, names[k], &s, detail);
      if (reason != nullptr) return reason;
      *out[k] = (fields_[i][0] == '-' ? -1.0 : 1.0) * (std::abs(d) + m / 60.0 + s / 3600.0);  // "-0 30 00" too
    }
    return Number(p + 6, "height", h, detail);
  }
  double x[3];
  const char* names[3] = {"x-ecef", "y-ecef", "z-ecef"};
  for (int i = 0; i < 3; ++i) {
    if (const char* reason = Number(p + i, names[i], &x[i], detail)) return reason;
  }
  std::vector<double> M(9);
  GeographicLib::Geocentric::WGS84().Reverse(x[0], x[1], x[2], *lat, *lon, *h, M);
  *R_ecef_enu = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(M.data());
  return nullptr;
}

// The σ columns present (absent cross terms are 0); a negative σ of an axis is damage.
const char* RtklibPosReader::ReadSigma(const int (&columns)[6], double sd[6], std::string* detail) const {
  for (int i = 0; i < 6; ++i) {
    sd[i] = 0.0;
    if (columns[i] < 0) continue;
    if (const char* reason = Number(columns[i], "σ", &sd[i], detail)) return reason;
    if (i < 3 && sd[i] < 0.0) {
      *detail = FormatText("column %d (σ) = %g m, negative", columns[i] + 1, sd[i]);
      return input_reason::kAbsurdValue;
    }
  }
  return nullptr;
}

const char* RtklibPosReader::Convert(const TextLine& line, std::string* detail) {
  if (static_cast<int>(fields_.size()) < layout_.tokens) {
    *detail =
        FormatText("%zu columns, the layout needs %d (%s)", fields_.size(), layout_.tokens, stats_.description.c_str());
    return kMissingFields;
  }
  SplitTime st;
  const bool calendar = fields_[0].find('/') != std::string_view::npos;
  if (!(calendar ? ParseCalendarTime(fields_[0], fields_[1], &st, detail)
                 : ParseWeekSeconds(fields_[0], fields_[1], &st, detail))) {
    return kBadTime;
  }
  if (layout_.jst) st.whole -= kJstMinusUtc;
  int leap = 0;
  const double t = ToLogTime(st, layout_.system, format_.time_scale, &leap);
  double q = 0;
  if (const char* reason = Number(layout_.q, "Q", &q, detail)) return reason;
  if (q != std::floor(q) || q < 0 || q > 7) {
    *detail = FormatText("column %d (Q) = %s: RTKLIB's Q is 1 fix, 2 float, 3 sbas, 4 dgps, 5 single, 6 ppp",
                         layout_.q + 1, QuoteToken(fields_[layout_.q]).c_str());
    return kUnknownQuality;
  }
  LogRecord fix;
  GnssRecord& g = fix.data.emplace<GnssRecord>();
  Mat3 R_ecef_enu = Mat3::Identity();
  if (const char* reason = ReadPosition(&g.lat_deg, &g.lon_deg, &g.alt_m, &R_ecef_enu, detail)) return reason;
  double sd[6], sdv[6];
  g.has_sigma = layout_.sd[0] >= 0 && layout_.sd[1] >= 0 && layout_.sd[2] >= 0;
  if (g.has_sigma) {
    if (const char* reason = ReadSigma(layout_.sd, sd, detail)) return reason;
  }
  LogRecord vel;
  GnssVelocityRecord& velocity = vel.data.emplace<GnssVelocityRecord>();
  const bool has_vel = layout_.vel[0] >= 0 && layout_.vel[1] >= 0 && layout_.vel[2] >= 0;
  Vec3 v;
  for (int i = 0; i < 3 && has_vel; ++i) {
    if (const char* reason = Number(layout_.vel[i], "velocity", &v[i], detail)) return reason;
  }
  velocity.has_sigma = has_vel && layout_.sdv[0] >= 0 && layout_.sdv[1] >= 0 && layout_.sdv[2] >= 0;
  if (velocity.has_sigma) {
    if (const char* reason = ReadSigma(layout_.sdv, sdv, detail)) return reason;
  }
  // Everything parsed: now the order, then what is kept.
  if (have_last_ && t <= last_t_) {
    *detail = FormatText("t = %.3f s is %s the previous solution's %.3f s", t, t == last_t_ ? "the same as" : "before",
                         last_t_);
    return t == last_t_ ? kDuplicate : kTimeBackwards;
  }
  have_last_ = true;
  last_t_ = t;
  if (q == 0 || q == 7) {
    ++stats_.dropped[q == 0 ? "no solution (Q 0)" : "dead reckoning (Q 7)"];
    return nullptr;
  }
  const FixQuality quality = kPosQuality[static_cast<int>(q) - 1];
  if (quality > format_.min_quality) {
    ++stats_.dropped[std::string("Q ") + FixQualityName(quality) + " (below --min-quality " +
                     FixQualityName(format_.min_quality) + ")"];
    return nullptr;
  }
  const bool ecef = layout_.position == Position::kEcef;
  g.t = t;
  // ECEF σ into ENU at the point: the full covariance rotated, its diagonal kept. Lat/lon σ are sdn sde sdu.
  if (g.has_sigma) {
    g.sigma_enu = ecef ? SigmaOf(R_ecef_enu.transpose() * Covariance(sd) * R_ecef_enu) : Floored(sd[1], sd[0], sd[2]);
  }
  if (!Accept(&fix, line.number, &lines_.issues(), FixQualityName(quality), leap)) return nullptr;
  pending_.push_back(fix);
  if (!has_vel) return nullptr;
  velocity.t = t;
  velocity.v_enu = ecef ? Vec3(R_ecef_enu.transpose() * v) : v;
  if (velocity.has_sigma) {
    velocity.sigma_enu =
        ecef ? SigmaOf(R_ecef_enu.transpose() * Covariance(sdv) * R_ecef_enu) : Floored(sdv[0], sdv[1], sdv[2]);
  }
  if (Accept(&vel, line.number, &lines_.issues(), FixQualityName(quality), leap)) pending_.push_back(vel);
  return nullptr;
}

}  // namespace

std::unique_ptr<RecordSource> OpenRtklibPos(const std::string& path, const InputOptions& options,
                                            const GnssFormatOptions& format) {
  return std::make_unique<RtklibPosReader>(path, options, format);
}

}  // namespace gins
