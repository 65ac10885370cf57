#include "core/io/i2nav.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <vector>

#include "core/io/i2nav_columns.h"
#include "core/io/log_writer.h"

namespace gins {
namespace {

using input_reason::kAbsurdValue;

// Standard gravity, only to judge units: |g| anywhere on the Earth's surface is within 0.3 % of it.
constexpr double kStandardGravity = 9.80665;
// The first IMU samples, held to learn the nominal period and check the units before anything is written.
constexpr size_t kProbeSamples = 50;
// An IMU interval longer than this many nominal periods is a gap.
constexpr double kGapFactor = 1.5;
// rad/s (~170 deg/s): a median turn rate over the first samples no ground vehicle reaches; degrees taken
// for radians give it at a gentle 3 deg/s.
constexpr double kProbeMaxGyro = 3.0;
constexpr double kWeek = 604800.0;  // s
// A turn rate above this, held for kSustainedFor, is degrees taken for radians: ~290 deg/s for a second is
// beyond any ground vehicle, while a corner of only 5 deg/s written in degrees reaches it.
constexpr double kMaxSustainedGyro = 5.0;  // rad/s
constexpr double kSustainedFor = 1.0;      // s

constexpr char kImuGap[] = "imu_gap";
constexpr char kExtraColumns[] = "extra_columns";

constexpr const char* kIncrementNames[] = {"t", "dθx", "dθy", "dθz", "dvx", "dvy", "dvz"};
constexpr const char* kRateNames[] = {"t", "gx", "gy", "gz", "ax", "ay", "az"};
constexpr const char* kGnssNames[] = {"t", "lat", "lon", "h", "σn", "σe", "σv"};
constexpr int kFirstSeven[] = {0, 1, 2, 3, 4, 5, 6};
constexpr int kGnssWithVelocity[] = {0, 1, 2, 3, 7, 8, 9};  // σ in columns 8-10 (KF-GINS gnssfileloader.h)

const int* SelectImu(size_t count) { return count >= 7 ? kFirstSeven : nullptr; }
const int* SelectGnss(size_t count) {
  return count == 7 ? kFirstSeven : count == 13 ? kGnssWithVelocity : nullptr;
}

ColumnSpec ImuSpec(I2navImuData data) {
  if (data == I2navImuData::kRates) {
    return {"IMU", "7 columns: t gx gy gz ax ay az (rad/s, m/s², FRD)", kRateNames, 7, SelectImu};
  }
  return {"IMU", "7 columns: t dθx dθy dθz dvx dvy dvz (rad, m/s, FRD)", kIncrementNames, 7, SelectImu};
}

const ColumnSpec kGnssSpec = {"GNSS", "7 columns, t lat lon h σn σe σv, or 13 with σ in columns 8-10", kGnssNames,
                              7, SelectGnss};

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

bool Near(double value, double target) { return value > target / 2.0 && value < target * 2.0; }

// FRD -> FLU: x stays, y and z change sign.
Vec3 FrdToFlu(const Vec3& v) { return Vec3(v.x(), -v.y(), -v.z()); }

// The IMU file as gins IMU samples: rates in FLU, stamped at the middle of their interval (increments) or
// at their time (rates), in time order.
class ImuStream {
 public:
  ImuStream(const I2navInputs& inputs, const InputOptions& options, ConvertedFile* file)
      : increments_(inputs.imu_data == I2navImuData::kIncrements),
        file_(file),
        reader_(ImuSpec(inputs.imu_data), file, options) {}

  bool Next(ImuSample* out);
  double nominal_interval() const { return static_cast<double>(nominal_); }

 private:
  void Probe();
  void CheckUnits();
  long double IncrementInterval(const Columns& raw, long double interval, bool first);
  bool Convert(const Columns& raw, long double interval, bool first, ImuSample* out);
  void CheckSustainedRate(const Columns& raw, const ImuSample& s, long double interval);

  const bool increments_;
  ConvertedFile* file_;
  ColumnReader reader_;
  std::deque<Columns> pending_;  // the probe's samples, not yet converted
  bool probed_ = false;
  bool have_prev_ = false;
  long double prev_t_ = 0.0L;
  long double nominal_ = 0.0L;
  // The current run of samples turning faster than kMaxSustainedGyro: since which line, for how long.
  uint64_t fast_since_line_ = 0;
  double fast_for_ = 0.0;
};

bool ImuStream::Next(ImuSample* out) {
  if (!probed_) Probe();
  Columns raw;
  for (;;) {
    if (!pending_.empty()) {
      raw = pending_.front();
      pending_.pop_front();
    } else if (!reader_.Next(&raw)) {
      return false;
    }
    // The first sample has no interval of its own: it takes the next one (Probe keeps a second sample).
    const bool first = !have_prev_;
    const long double interval = first ? pending_.front().t - raw.t : raw.t - prev_t_;
    prev_t_ = raw.t;
    have_prev_ = true;
    if (Convert(raw, interval, first, out)) {
      CheckSustainedRate(raw, *out, interval);
      return true;
    }
  }
}

void ImuStream::CheckSustainedRate(const Columns& raw, const ImuSample& s, long double interval) {
  if (s.gyro.norm() <= kMaxSustainedGyro) {
    fast_for_ = 0.0;
    return;
  }
  if (fast_for_ == 0.0) fast_since_line_ = raw.line;
  fast_for_ += std::min(static_cast<double>(interval), kGapFactor * static_cast<double>(nominal_));
  if (fast_for_ < kSustainedFor) return;
  reader_.issues().Refuse(
      fast_since_line_,
      FormatText("the gyro turns faster than %g rad/s (%.0f deg/s) for %g s, to line %llu: %s", kMaxSustainedGyro,
                 kMaxSustainedGyro * kRadToDeg, kSustainedFor, static_cast<unsigned long long>(raw.line),
                 increments_ ? "are the angle increments in degrees?" : "deg/s instead of rad/s?"));
}

void ImuStream::Probe() {
  probed_ = true;
  Columns c;
  while (pending_.size() < kProbeSamples && reader_.Next(&c)) pending_.push_back(c);
  if (pending_.size() < 2) {
    throw InputError(file_->path + ": " + (pending_.empty() ? "no usable IMU lines" : "only one usable IMU line") +
                     " in " + std::to_string(file_->lines) +
                     " lines; the conversion needs two or more to know the sampling interval");
  }
  if (file_->columns > 7) {
    const std::string extra =
        file_->columns == 8 ? "column 8 is" : FormatText("columns 8-%d are", file_->columns);
    reader_.issues().Warn(pending_.front().line, kExtraColumns,
                          FormatText("%d columns: %s not IMU data, ignored (OB_GINS's IMU/ODO variant puts an "
                                     "odometer speed in column 8; not converted)",
                                     file_->columns, extra.c_str()));
  }
  std::vector<double> intervals;
  for (size_t i = 1; i < pending_.size(); ++i) {
    intervals.push_back(static_cast<double>(pending_[i].t - pending_[i - 1].t));
  }
  nominal_ = Median(intervals);
  CheckUnits();
}

// The columns must be what the format says. Gravity dominates the specific force of a ground vehicle, so
// the median |f| over the first samples is |g| within a factor of 2 in any unit that is right; the same
// statistic in the wrong unit or the wrong kind (rate for increment) is off by 1/Δt or 9.8.
void ImuStream::CheckUnits() {
  std::vector<double> column_acc, column_gyro, f, w;
  for (size_t i = 0; i < pending_.size(); ++i) {
    const Columns& s = pending_[i];
    const double dt = static_cast<double>(i > 0 ? s.t - pending_[i - 1].t : pending_[1].t - s.t);
    if (dt > kGapFactor * static_cast<double>(nominal_)) continue;
    column_gyro.push_back(Vec3(s.v[1], s.v[2], s.v[3]).norm());
    column_acc.push_back(Vec3(s.v[4], s.v[5], s.v[6]).norm());
    f.push_back(increments_ ? column_acc.back() / dt : column_acc.back());
    w.push_back(increments_ ? column_gyro.back() / dt : column_gyro.back());
  }
  const double g = kStandardGravity, dt = static_cast<double>(nominal_);
  const double acc = Median(column_acc), med_f = Median(f), med_w = Median(w);
  const std::string over = FormatText(" (median over lines %llu-%llu, IMU period %.6g s)",
                                      static_cast<unsigned long long>(pending_.front().line),
                                      static_cast<unsigned long long>(pending_.back().line), dt);
  const uint64_t line = pending_.front().line;
  FileIssues& issues = reader_.issues();
  if (!Near(med_f, g)) {
    if (increments_ && Near(acc, g)) {
      issues.Refuse(line, FormatText("the velocity columns look like accelerations, not increments: their "
                                     "magnitude is %.4g m/s² ≈ |g|, where increments would be ≈ |g|·Δt = %.3g m/s",
                                     acc, g * dt) + over + "; for a file of rates use --imu-data rates");
    }
    if (!increments_ && Near(acc / dt, g)) {
      issues.Refuse(line, FormatText("the accelerometer columns look like velocity increments, not rates: their "
                                     "magnitude is %.4g ≈ |g|·Δt = %.3g m/s",
                                     acc, g * dt) + over + "; for increments use --imu-data increments");
    }
    if (increments_ && Near(acc, 1.0)) {
      issues.Refuse(line, FormatText("the velocity columns look like accelerations in g, not increments: their "
                                     "magnitude is %.4g ≈ 1",
                                     acc) + over);
    }
    if (Near(med_f, 1.0)) {
      issues.Refuse(line, FormatText("the accelerometer implies |f| = %.4g, ≈ 1 where m/s² would give ≈ |g| = "
                                     "%.4g: the file looks like g units",
                                     med_f, g) + over);
    }
    issues.Refuse(line, FormatText("the accelerometer implies |f| = %.4g m/s², far from |g| = %.4g: not %s in "
                                   "the i2Nav units",
                                   med_f, g, increments_ ? "velocity increments (m/s)" : "accelerations (m/s²)") +
                            over);
  }
  if (med_w > kProbeMaxGyro) {
    issues.Refuse(line, FormatText("the gyro implies a turn rate of %.4g rad/s (%.0f deg/s): %s",
                                   med_w, med_w * kRadToDeg,
                                   increments_ ? "are the angle increments in degrees?" : "deg/s instead of rad/s?") +
                            over);
  }
}

// The interval an increment covers. Past a gap the increments either span the whole gap (the IMU went on
// integrating) or one nominal period (samples were lost); the specific force tells which, since only the
// right one puts it near |g|.
long double ImuStream::IncrementInterval(const Columns& raw, long double interval, bool first) {
  if (interval <= kGapFactor * nominal_) return interval;
  if (first) return nominal_;  // the next interval says nothing about the first sample's own
  const double dv = Vec3(raw.v[4], raw.v[5], raw.v[6]).norm();
  const double f_gap = dv / static_cast<double>(interval), f_nominal = dv / static_cast<double>(nominal_);
  const bool lost = std::abs(std::log(f_nominal / kStandardGravity)) < std::abs(std::log(f_gap / kStandardGravity));
  reader_.issues().Warn(
      raw.line, kImuGap,
      FormatText("%.6g s since the previous sample (nominal %.6g s): %s", static_cast<double>(interval),
                 static_cast<double>(nominal_),
                 lost ? FormatText("samples lost, the increments cover one period (|f| %.3g m/s² over it, %.3g over "
                                   "the gap)", f_nominal, f_gap).c_str()
                      : FormatText("the increments span the gap (|f| %.3g m/s² over it)", f_gap).c_str()));
  return lost ? nominal_ : interval;
}

bool ImuStream::Convert(const Columns& raw, long double interval, bool first, ImuSample* out) {
  const Vec3 gyro_frd(raw.v[1], raw.v[2], raw.v[3]), acc_frd(raw.v[4], raw.v[5], raw.v[6]);
  long double t = raw.t;
  double dt = 1.0;
  if (increments_) {
    const long double covered = IncrementInterval(raw, interval, first);
    dt = static_cast<double>(covered);
    t -= covered / 2.0L;
  }
  // Rates keep the file's time exactly (v[0] is the direct parse; rounding t again could differ by an ulp).
  out->t = increments_ ? static_cast<double>(t) : raw.v[0];
  out->gyro = FrdToFlu(gyro_frd / dt);
  out->acc = FrdToFlu(acc_frd / dt);
  const char* const* names = increments_ ? kIncrementNames : kRateNames;
  const std::string per = increments_ ? FormatText(" over Δt = %.6g s", dt) : std::string();
  for (int i = 0; i < 6; ++i) {
    const double value = i < 3 ? gyro_frd[i] / dt : acc_frd[i - 3] / dt;
    const double limit = i < 3 ? log_limits::kMaxAbsGyro : log_limits::kMaxAbsAcc;
    if (std::abs(value) <= limit) continue;
    const char* hint = i < 3 ? (increments_ ? "angle increments in degrees?" : "deg/s instead of rad/s?")
                             : (increments_ ? "a rate, not an increment?" : "a corrupted field?");
    reader_.issues().Damage(raw.line, kAbsurdValue,
                            FormatText("column %d (%s) = %.6g%s is %.6g %s, beyond ±%g: %s", i + 2, names[i + 1],
                                       i < 3 ? gyro_frd[i] : acc_frd[i - 3], per.c_str(), value,
                                       i < 3 ? "rad/s" : "m/s²", limit, hint));
    return false;
  }
  if (!(out->t > 0.0)) {
    reader_.issues().Damage(raw.line, kAbsurdValue,
                            FormatText("the sample's time %.6f is not > 0 (gins needs positive times)", out->t));
    return false;
  }
  return true;
}

// The GNSS file as gins GNSS records: σ reordered to east, north, up; no heading.
class GnssStream {
 public:
  GnssStream(const InputOptions& options, ConvertedFile* file)
      : reader_(kGnssSpec, file, options) {}
  bool Next(GnssRecord* g);

 private:
  ColumnReader reader_;
};

// Ranges as the gins reader checks them (log_limits), so that the log reads back without damage.
std::string CheckFix(const Columns& c) {
  const double* v = c.v.data();
  if (!(v[0] > 0.0)) return FormatText("column 1 (t) = %.6f, gins needs times > 0", v[0]);
  if (std::abs(v[1]) > log_limits::kMaxAbsLatDeg) return FormatText("column 2 (lat) = %.10g deg, beyond ±90", v[1]);
  if (std::abs(v[2]) > log_limits::kMaxAbsLonDeg) return FormatText("column 3 (lon) = %.10g deg, beyond ±180", v[2]);
  if (!(v[3] > log_limits::kMinAlt && v[3] < log_limits::kMaxAlt)) {
    return FormatText("column 4 (h) = %.6g m, outside (%g, %g)", v[3], log_limits::kMinAlt, log_limits::kMaxAlt);
  }
  const int first_sigma_column = c.count == 13 ? 8 : 5;
  for (int i = 4; i < 7; ++i) {
    if (!(v[i] > 0.0 && v[i] < log_limits::kMaxSigma)) {
      return FormatText("column %d (%s) = %.6g m, σ must be in (0, %g)", first_sigma_column + i - 4, kGnssNames[i],
                        v[i], log_limits::kMaxSigma);
    }
  }
  return {};
}

bool GnssStream::Next(GnssRecord* g) {
  Columns c;
  while (reader_.Next(&c)) {
    const std::string absurd = CheckFix(c);
    if (!absurd.empty()) {
      reader_.issues().Damage(c.line, kAbsurdValue, absurd);
      continue;
    }
    g->t = c.v[0];
    g->lat_deg = c.v[1];
    g->lon_deg = c.v[2];
    g->alt_m = c.v[3];
    g->heading_deg = 0.0;
    g->heading_valid = false;
    g->has_sigma = true;
    g->sigma_enu = Vec3(c.v[5], c.v[4], c.v[6]);  // file: north, east, vertical
    return true;
  }
  return false;
}

std::string Header(const I2navInputs& in, double period) {
  const bool inc = in.imu_data == I2navImuData::kIncrements;
  return "gins convert --format i2nav: IMU " + in.imu_path +
         (inc ? " (increments dθ rad, dv m/s over (t_prev, t], FRD) as rates at interval midpoints"
              : " (rates rad/s, m/s² at t, FRD)") +
         FormatText(", FLU, period %.6g s; GNSS ", period) + in.gnss_path +
         " (lat lon h σn σe σv) with σ east north up, heading_valid 0; times as in the files";
}

// Both files must share a time base: ranges that do not overlap mean one is, e.g., GPS seconds of week and
// the other unix time, and the log would hold two separate halves.
void CheckTimeBases(const I2navConversion& c) {
  const ConvertedFile& i = c.imu;
  const ConvertedFile& g = c.gnss;
  if (i.t_last >= g.t_first && g.t_last >= i.t_first) return;
  std::string hint = "different time bases?";
  if ((i.t_last <= kWeek) != (g.t_last <= kWeek)) {
    hint = "different time bases: one looks like GPS seconds of week (0-604800), the other not";
  }
  throw InputError(i.path + FormatText(": IMU times [%.3f, %.3f] s and the GNSS times [%.3f, %.3f] s of ", i.t_first,
                                       i.t_last, g.t_first, g.t_last) +
                   g.path + " do not overlap: " + hint);
}

void AppendFileSummary(const char* what, const ConvertedFile& f, std::string* out) {
  *out += FormatText("  %-4s ", what) + f.path +
          FormatText(": %llu lines, %llu records", static_cast<unsigned long long>(f.lines),
                     static_cast<unsigned long long>(f.written));
  if (f.has_range) *out += FormatText(", t %.3f .. %.3f s, %d columns", f.t_first, f.t_last, f.columns);
  *out += "\n";
  *out += FormatIssueCounts("skipped", f.skipped, f.issues);
  *out += FormatIssueCounts("warning", f.warnings, f.issues);
}

}  // namespace

I2navConversion ConvertI2nav(const I2navInputs& inputs, const InputOptions& options, const std::string& out_path) {
  I2navConversion c;
  c.out_path = out_path;
  c.imu.path = inputs.imu_path;
  c.gnss.path = inputs.gnss_path;
  ImuStream imu(inputs, options, &c.imu);
  GnssStream gnss(options, &c.gnss);
  LogWriter out(out_path);
  ImuSample s;
  GnssRecord g;
  bool have_imu = imu.Next(&s);  // the IMU probe runs first: units and period are known before writing
  bool have_gnss = gnss.Next(&g);
  c.imu_interval = imu.nominal_interval();
  c.header = Header(inputs, c.imu_interval);
  out.Comment(c.header);
  while (have_imu || have_gnss) {
    if (have_imu && (!have_gnss || s.t <= g.t)) {  // ties: IMU first
      out.Add({s});
      ++c.imu.written;
      have_imu = imu.Next(&s);
    } else {
      out.Add({g});
      ++c.gnss.written;
      have_gnss = gnss.Next(&g);
    }
  }
  if (c.gnss.written == 0) {
    throw InputError(c.gnss.path + ": no usable GNSS lines in " + std::to_string(c.gnss.lines) + " lines");
  }
  CheckTimeBases(c);
  out.Commit();
  return c;
}

std::string FormatConversionSummary(const I2navConversion& c) {
  std::string out = "gins convert: i2nav -> " + c.out_path +
                    FormatText(" (%llu IMU, %llu GNSS records; IMU period %.6g s)\n",
                               static_cast<unsigned long long>(c.imu.written),
                               static_cast<unsigned long long>(c.gnss.written), c.imu_interval);
  AppendFileSummary("IMU", c.imu, &out);
  AppendFileSummary("GNSS", c.gnss, &out);
  return out;
}

}  // namespace gins
