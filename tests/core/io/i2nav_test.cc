// The i2Nav converter (core/io/i2nav.h): conventions (increments -> midpoint rates, FRD -> FLU, σ order,
// merge order), streaming details (gaps, extra columns, gzip), and that every kind of bad input is named
// by file and line, skipped and counted or refused.
#include "core/io/i2nav.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kT0 = 357000.0;  // GPS seconds of week, as in i2Nav's sample data

std::string Num(double v) {  // shortest text that reads back to the same double
  char buf[32];
  return std::string(buf, std::to_chars(buf, buf + sizeof(buf), v).ptr);
}

std::string Fixed(double t, int digits) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, t);
  return buf;
}

// FLU rates linear in time: the mean over any interval is the rate at its midpoint exactly, so the
// converted rates must equal these at their stamps, to rounding.
Vec3 GyroFlu(double s) { return Vec3(0.01 + 0.002 * s, -0.02 + 0.001 * s, 0.3 - 0.01 * s); }
Vec3 AccFlu(double s) { return Vec3(0.5 - 0.05 * s, 0.2 + 0.02 * s, 9.8 + 0.01 * s); }
Vec3 Frd(const Vec3& flu) { return Vec3(flu.x(), -flu.y(), -flu.z()); }

// Jittered sample times in units of 1/1024 s (~200 Hz): binary fractions, so that the times, their
// differences and midpoints are exact in the file's text, in double and in the converter's long double.
std::vector<double> SampleTimes(size_t n) {
  const int ticks[] = {5, 6, 4, 5, 7, 5, 3};
  std::vector<double> t = {kT0};
  while (t.size() < n) t.push_back(t.back() + ticks[t.size() % 7] / 1024.0);
  return t;
}

// i2Nav IMU lines for GyroFlu/AccFlu at the given times: increments over (t_prev, t] in FRD. The first
// sample's interval is taken as long as the next one, as the converter assumes.
std::string IncrementFile(const std::vector<double>& t) {
  std::string text;
  for (size_t k = 0; k < t.size(); ++k) {
    const double prev = k > 0 ? t[k - 1] : t[0] - (t[1] - t[0]);
    const double dt = t[k] - prev, mid = 0.5 * (t[k] + prev) - kT0;
    const Vec3 dtheta = Frd(GyroFlu(mid)) * dt, dv = Frd(AccFlu(mid)) * dt;
    text += Fixed(t[k], 10);
    for (int i = 0; i < 3; ++i) text += " " + Num(dtheta[i]);
    for (int i = 0; i < 3; ++i) text += " " + Num(dv[i]);
    text += "\n";
  }
  return text;
}

std::string GnssLine(double t, double lat = 30.4604325443, double sn = 0.008, double se = 0.011, double su = 0.036) {
  return Fixed(t, 10) + " " + Fixed(lat, 10) + " 114.4725046685 23.000 " + Num(sn) + " " + Num(se) + " " + Num(su);
}

// A vehicle at rest at 200 Hz: n lines from kT0, the decimal time stamps real files have.
std::string RestImuLine(int k) {
  const double dt = 0.005;
  return Fixed(kT0 + k * dt, 3) + " " + Num(1e-4 * dt) + " " + Num(-2e-4 * dt) + " " + Num(3e-4 * dt) + " " +
         Num(0.01 * dt) + " " + Num(-0.02 * dt) + " " + Num(-9.8 * dt);
}
std::vector<std::string> RestImu(int n) {
  std::vector<std::string> lines;
  for (int k = 0; k < n; ++k) lines.push_back(RestImuLine(k));
  return lines;
}
std::vector<std::string> RestGnss() { return {GnssLine(kT0 + 0.1), GnssLine(kT0 + 0.2), GnssLine(kT0 + 0.3)}; }

std::string Join(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  return text;
}

struct LogContent {
  std::vector<ImuSample> imu;
  std::vector<GnssRecord> gnss;
  std::vector<char> order;  // 'I' / 'G' per record
  std::string first_line;
};

// Reads a converted log back with the gins reader, refusing any damage.
LogContent ReadLog(const std::string& path) {
  InputOptions stop;
  stop.on_error = InputErrorPolicy::kStop;
  LogReader reader(path, stop);
  LogContent log;
  LogRecord r;
  while (reader.Next(&r)) {
    if (r.is<ImuSample>()) log.imu.push_back(r.get<ImuSample>());
    if (r.is<GnssRecord>()) log.gnss.push_back(r.get<GnssRecord>());
    log.order.push_back(r.is<ImuSample>() ? 'I' : 'G');
  }
  EXPECT_EQ(reader.stats().total_skipped(), 0u);
  return log;
}

class I2navTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::MakeTempDir("i2nav"); }

  I2navConversion Convert(const std::string& imu_text, const std::string& gnss_text, const InputOptions& options = {},
                          I2navImuData data = I2navImuData::kIncrements, const std::string& out_name = "log.txt") {
    test::WriteFile(imu_path(), imu_text);
    test::WriteFile(gnss_path(), gnss_text);
    I2navInputs in;
    in.imu_path = imu_path();
    in.gnss_path = gnss_path();
    in.imu_data = data;
    return ConvertI2nav(in, options, dir_ + "/" + out_name);
  }

  // The conversion must fail with an InputError containing every one of `parts`, and leave no log.
  void ExpectRefused(const std::string& imu_text, const std::string& gnss_text, const std::vector<std::string>& parts,
                     const InputOptions& options = {}, I2navImuData data = I2navImuData::kIncrements) {
    try {
      Convert(imu_text, gnss_text, options, data);
      ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
      const std::string what = e.what();
      for (const auto& p : parts) EXPECT_NE(what.find(p), std::string::npos) << "'" << p << "' not in: " << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
    EXPECT_FALSE(std::filesystem::exists(dir_ + "/log.txt"));
    size_t files = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir_)) files += e.is_regular_file();
    EXPECT_EQ(files, 2u);  // the inputs only: no temporary left
  }

  std::string imu_path() const { return dir_ + "/imu.txt"; }
  std::string gnss_path() const { return dir_ + "/gnss.txt"; }
  std::string dir_;
};

TEST_F(I2navTest, IncrementsBecomeMidpointRatesInFluToRounding) {
  const std::vector<double> t = SampleTimes(120);
  // Fixes at a few times, one of them exactly at the midpoint of samples 0 and 1 (a tie: IMU first).
  const double tie = 0.5 * (t[0] + t[1]);
  const I2navConversion c =
      Convert(IncrementFile(t), Join({GnssLine(tie, 30.1, 0.01, 0.02, 0.03), GnssLine(kT0 + 0.25, 30.2)}));
  EXPECT_EQ(c.imu.written, t.size());
  EXPECT_EQ(c.gnss.written, 2u);
  EXPECT_TRUE(c.imu.skipped.empty() && c.gnss.skipped.empty() && c.imu.warnings.empty());
  EXPECT_NEAR(c.imu_interval, 5.0 / 1024.0, 1e-15);

  const LogContent log = ReadLog(dir_ + "/log.txt");
  ASSERT_EQ(log.imu.size(), t.size());
  for (size_t k = 0; k < t.size(); ++k) {
    SCOPED_TRACE("sample " + std::to_string(k));
    const double prev = k > 0 ? t[k - 1] : t[0] - (t[1] - t[0]);  // the first takes the next interval
    const double mid = 0.5 * (prev + t[k]);
    EXPECT_NEAR(log.imu[k].t, mid, 1e-9);
    EXPECT_LT((log.imu[k].gyro - GyroFlu(mid - kT0)).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT((log.imu[k].acc - AccFlu(mid - kT0)).cwiseAbs().maxCoeff(), 1e-9);
  }
  // Axes: a left turn (+z FLU) and gravity's upward specific force (+z FLU) are −z in the FRD file.
  EXPECT_GT(log.imu[0].gyro.z(), 0.29);
  EXPECT_GT(log.imu[0].acc.z(), 9.7);
  EXPECT_GT(log.imu[0].acc.y(), 0.19);

  ASSERT_EQ(log.gnss.size(), 2u);
  EXPECT_EQ(log.order[0], 'I');
  EXPECT_EQ(log.order[1], 'I');  // sample 1's midpoint equals the fix's time: IMU first
  EXPECT_EQ(log.order[2], 'G');
  EXPECT_EQ(log.gnss[0].t, tie);
  EXPECT_EQ(log.gnss[0].lat_deg, 30.1);
  EXPECT_EQ(log.gnss[0].lon_deg, 114.4725046685);
  EXPECT_EQ(log.gnss[0].alt_m, 23.0);
  EXPECT_FALSE(log.gnss[0].heading_valid);
  ASSERT_TRUE(log.gnss[0].has_sigma);
  EXPECT_EQ(log.gnss[0].sigma_enu, Vec3(0.02, 0.01, 0.03));  // file σn σe σu -> east north up
}

TEST_F(I2navTest, DecimalTimeStampsKeepRatesExact) {
  // Real files stamp 200 Hz as 357000.005, ...: the interval from double times would be off by ~1e-8
  // relative; the converter's extended precision keeps it to ~1e-12.
  const I2navConversion c = Convert(Join(RestImu(400)), Join(RestGnss()));
  EXPECT_EQ(c.imu.written, 400u);
  const LogContent log = ReadLog(dir_ + "/log.txt");
  for (size_t k = 1; k < log.imu.size(); ++k) {
    EXPECT_NEAR(log.imu[k].t, kT0 + 0.005 * k - 0.0025, 1e-9);
    EXPECT_NEAR(log.imu[k].acc.z(), 9.8, 1e-9);
    EXPECT_NEAR(log.imu[k].acc.y(), 0.02, 1e-9);
    EXPECT_NEAR(log.imu[k].gyro.z(), -3e-4, 1e-12);
  }
  EXPECT_EQ(test::ReadFile(dir_ + "/log.txt").rfind("# gins convert --format i2nav: IMU " + imu_path(), 0), 0u);
}

TEST_F(I2navTest, RatesVariantKeepsTimesAndMapsAxes) {
  std::vector<std::string> lines;
  for (int k = 0; k < 100; ++k) lines.push_back(Fixed(kT0 + 0.01 * k, 2) + " 0.1 0.2 0.3 0.5 0.25 -9.8");
  Convert(Join(lines), Join(RestGnss()), {}, I2navImuData::kRates);
  const LogContent log = ReadLog(dir_ + "/log.txt");
  ASSERT_EQ(log.imu.size(), 100u);
  EXPECT_EQ(log.imu[3].t, 357000.03);
  EXPECT_EQ(log.imu[3].gyro, Vec3(0.1, -0.2, -0.3));
  EXPECT_EQ(log.imu[3].acc, Vec3(0.5, -0.25, 9.8));
}

TEST_F(I2navTest, GzipCommasCommentsAndThirteenColumnGnss) {
  const std::string gz_imu = dir_ + "/imu.txt.gz";
  std::string imu = "% i2Nav IMU, commas\n";
  for (const auto& l : RestImu(100)) {
    std::string c = l;
    for (char& ch : c) ch = ch == ' ' ? ',' : ch;
    imu += c + "\r\n";
  }
  gzFile f = gzopen(gz_imu.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(gzwrite(f, imu.data(), static_cast<unsigned>(imu.size())), static_cast<int>(imu.size()));
  ASSERT_EQ(gzclose(f), Z_OK);
  // 13 columns: t lat lon h, velocity, σ (columns 8-10), velocity σ.
  test::WriteFile(gnss_path(), "# t lat lon h vn ve vd sn se su svn sve svd\n" + Fixed(kT0 + 0.1, 1) +
                                   " 30.5 114.5 20 1 2 3 0.1 0.2 0.3 nan nan nan\n");
  I2navInputs in{gz_imu, gnss_path(), I2navImuData::kIncrements};
  const I2navConversion c = ConvertI2nav(in, {}, dir_ + "/log.txt.gz");
  EXPECT_EQ(c.imu.written, 100u);
  EXPECT_EQ(c.gnss.columns, 13);
  const LogContent log = ReadLog(dir_ + "/log.txt.gz");
  ASSERT_EQ(log.gnss.size(), 1u);
  EXPECT_EQ(log.gnss[0].sigma_enu, Vec3(0.2, 0.1, 0.3));
  EXPECT_EQ(log.imu.size(), 100u);
}

TEST_F(I2navTest, ExtraImuColumnsAreIgnoredWithAWarning) {
  std::vector<std::string> lines = RestImu(100);
  for (auto& l : lines) l += " 12.5";  // OB_GINS's odometer column
  const I2navConversion c = Convert(Join(lines), Join(RestGnss()));
  EXPECT_EQ(c.imu.written, 100u);
  ASSERT_EQ(c.imu.warnings.count("extra_columns"), 1u);
  EXPECT_NE(FormatConversionSummary(c).find("warning extra_columns: 1 (first at line 1: 8 columns: column 8 is not IMU data"), std::string::npos)
      << FormatConversionSummary(c);
}

TEST_F(I2navTest, GapOfLostSamplesUsesTheNominalPeriod) {
  std::vector<std::string> lines = RestImu(100);
  lines.erase(lines.begin() + 60, lines.begin() + 65);  // samples 60-64 lost with their increments
  const I2navConversion c = Convert(Join(lines), Join(RestGnss()));
  ASSERT_EQ(c.imu.warnings.count("imu_gap"), 1u);
  EXPECT_EQ(c.imu.issues.at(0).line, 61u);
  const LogContent log = ReadLog(dir_ + "/log.txt");
  EXPECT_NEAR(log.imu[60].t, kT0 + 0.005 * 65 - 0.0025, 1e-9);
  EXPECT_NEAR(log.imu[60].acc.z(), 9.8, 1e-6);  // the gap logic; precision is DecimalTimeStampsKeepRatesExact's
}

TEST_F(I2navTest, GapSpannedByOneIncrementUsesTheWholeGap) {
  std::vector<std::string> lines = RestImu(100);
  lines.erase(lines.begin() + 60, lines.begin() + 64);
  const double dt = 0.025;  // the increment of sample 64 spans (59, 64]: 5 periods
  lines[60] = Fixed(kT0 + 0.005 * 64, 3) + " 0 0 0 0 0 " + Num(-9.8 * dt);
  const I2navConversion c = Convert(Join(lines), Join(RestGnss()));
  ASSERT_EQ(c.imu.warnings.count("imu_gap"), 1u);
  const LogContent log = ReadLog(dir_ + "/log.txt");
  EXPECT_NEAR(log.imu[60].t, kT0 + 0.005 * 64 - dt / 2, 1e-9);
  EXPECT_NEAR(log.imu[60].acc.z(), 9.8, 1e-6);
}

// One damaged line in otherwise good files: skipped and counted under skip, named under stop.
struct DamageCase {
  bool imu;          // the IMU file (else the GNSS file)
  int line;          // 1-based line replaced
  std::string text;  // its new text
  std::string reason;
  std::string detail;  // part of the message
};

std::vector<DamageCase> DamageCases() {
  const std::string t60 = Fixed(kT0 + 0.005 * 59, 3);  // line 60's own time
  const std::string rest = " 0 0 0 0 0 -0.049";
  return {
      {true, 60, t60 + " 1 2", "missing_fields", "IMU line with 3 columns; the i2Nav IMU file has 7 columns"},
      {true, 60, t60 + rest + " 1", "extra_fields", "8 columns where the file's first line has 7"},
      {true, 60, t60 + " 0 abc 0 0 0 -0.049", "bad_number", "column 3 (dθy) 'abc' is not a number"},
      {true, 60, t60 + " 0 0 nan 0 0 -0.049", "non_finite", "column 4 (dθz) 'nan' is not finite"},
      {true, 60, t60 + " 0 0 0 0 -inf -0.049", "non_finite", "column 6 (dvy) '-inf' is not finite"},
      {true, 60, Fixed(kT0 + 0.1, 3) + rest, "out_of_order", "is older than the previous line's"},
      {true, 60, Fixed(kT0 + 0.005 * 58, 3) + rest, "duplicate", "a second IMU line at t = 357000.290000"},
      {true, 60, t60 + " 0.2 0 0 0 0 -0.049", "absurd_value", "is 40 rad/s, beyond ±35: angle increments in degrees?"},
      {true, 10, t60.substr(0, 6) + ".045 0 0 0 1.5 0 -0.049", "absurd_value", "is 300 m/s², beyond ±200"},
      {true, 60, "-1" + rest, "absurd_value", "time must be >= 0"},
      {true, 60, "2e10" + rest, "absurd_value", "column 1 (t) = 20000000000.000000, beyond 1e+10 s"},
      {false, 2, GnssLine(kT0 + 0.2, 91.0), "absurd_value", "column 2 (lat) = 91 deg, beyond ±90"},
      {false, 2, Fixed(kT0 + 0.2, 3) + " 30 -181 20 0.1 0.1 0.1", "absurd_value", "column 3 (lon) = -181 deg"},
      {false, 2, GnssLine(kT0 + 0.2, 30.0, 0.0), "absurd_value", "column 5 (σn) = 0 m, σ must be in (0, 10000)"},
      {false, 2, GnssLine(kT0 + 0.2, 30.0, 0.1, -0.1), "absurd_value", "column 6 (σe) = -0.1 m"},
      {false, 2, Fixed(kT0 + 0.2, 3) + " 30 114 20", "missing_fields", "GNSS line with 4 columns"},
      {false, 2, GnssLine(kT0 + 0.2) + " 7", "extra_fields", "GNSS line with 8 columns"},
      {false, 2, Fixed(kT0 + 0.2, 3) + " 30 114 2O 0.1 0.1 0.1", "bad_number", "column 4 (h) '2O' is not a number"},
      {false, 2, GnssLine(kT0 + 0.1), "duplicate", "a second GNSS line"},
      {false, 3, GnssLine(kT0 + 0.05), "out_of_order", "older than the previous line's"},
  };
}

void Apply(const DamageCase& d, std::vector<std::string>* imu, std::vector<std::string>* gnss) {
  (d.imu ? *imu : *gnss)[d.line - 1] = d.text;
}

TEST_F(I2navTest, EachDamagedLineIsNamedUnderStop) {
  InputOptions stop;
  stop.on_error = InputErrorPolicy::kStop;
  for (const DamageCase& d : DamageCases()) {
    SCOPED_TRACE(d.text);
    std::vector<std::string> imu = RestImu(100), gnss = RestGnss();
    Apply(d, &imu, &gnss);
    const std::string where = (d.imu ? imu_path() : gnss_path()) + ":" + std::to_string(d.line) + ": ";
    ExpectRefused(Join(imu), Join(gnss), {where + d.reason + ": ", d.detail}, stop);
  }
}

TEST_F(I2navTest, EachDamagedLineIsSkippedAndCountedUnderSkip) {
  for (const DamageCase& d : DamageCases()) {
    SCOPED_TRACE(d.text);
    std::vector<std::string> imu = RestImu(100), gnss = RestGnss();
    Apply(d, &imu, &gnss);
    const I2navConversion c = Convert(Join(imu), Join(gnss));
    const ConvertedFile& f = d.imu ? c.imu : c.gnss;
    EXPECT_EQ(f.total_skipped(), 1u);
    ASSERT_EQ(f.skipped.count(d.reason), 1u);
    const auto issue = std::find_if(f.issues.begin(), f.issues.end(),
                                    [&](const InputIssue& i) { return i.reason == d.reason; });
    ASSERT_NE(issue, f.issues.end());
    EXPECT_EQ(issue->line, static_cast<uint64_t>(d.line));
    EXPECT_NE(issue->detail.find(d.detail), std::string::npos) << issue->detail;
    EXPECT_EQ(c.imu.written + c.gnss.written, 102u);
    const std::string summary = FormatConversionSummary(c);
    EXPECT_NE(summary.find("skipped " + d.reason + ": 1 (first at line " + std::to_string(d.line) + ": "),
              std::string::npos)
        << summary;
    ReadLog(dir_ + "/log.txt");  // and the log reads back without damage
  }
}

TEST_F(I2navTest, TooManyDamagedLinesStop) {
  InputOptions options;
  options.max_errors = 2;
  std::vector<std::string> imu = RestImu(100);
  for (int k = 70; k < 73; ++k) imu[k] = "x 0 0 0 0 0 -0.049";
  ExpectRefused(Join(imu), Join(RestGnss()), {imu_path() + ":73: too many damaged lines (3), last: bad_number"},
                options);
}

TEST_F(I2navTest, GpsWeekRolloverIsNamed) {
  std::vector<std::string> imu = RestImu(100);
  imu.push_back("0.001 0 0 0 0 0 -0.049");
  InputOptions stop;
  stop.on_error = InputErrorPolicy::kStop;
  ExpectRefused(Join(imu), Join(RestGnss()), {imu_path() + ":101: out_of_order: ", "GPS week rollover"}, stop);
}

// Files whose columns are not what the format says are refused whatever the policy, at their first line.
TEST_F(I2navTest, RatesGivenAsIncrementsAreRefused) {
  std::vector<std::string> imu;
  for (int k = 0; k < 100; ++k) imu.push_back(Fixed(kT0 + 0.005 * k, 3) + " 0.01 0.02 0.03 0.1 0.2 -9.81");
  ExpectRefused(Join(imu), Join(RestGnss()),
                {imu_path() + ":1: the velocity columns look like accelerations, not increments", "--imu-data rates"});
}

TEST_F(I2navTest, IncrementsGivenAsRatesAreRefused) {
  ExpectRefused(Join(RestImu(100)), Join(RestGnss()),
                {imu_path() + ":1: the accelerometer columns look like velocity increments, not rates",
                 "--imu-data increments"},
                {}, I2navImuData::kRates);
}

TEST_F(I2navTest, AccelerometerInGIsRefused) {
  std::vector<std::string> imu;
  for (int k = 0; k < 100; ++k) imu.push_back(Fixed(kT0 + 0.005 * k, 3) + " 0 0 0 0 0 " + Num(-0.005));
  ExpectRefused(Join(imu), Join(RestGnss()), {imu_path() + ":1: ", "g units", "median over lines 1-50"});
}

TEST_F(I2navTest, GyroInDegreesIsRefused) {
  std::vector<std::string> imu;  // a steady 20 deg/s turn written in degrees: 20 "rad/s"
  for (int k = 0; k < 100; ++k) imu.push_back(Fixed(kT0 + 0.005 * k, 3) + " 0 0 0.1 0 0 -0.049");
  ExpectRefused(Join(imu), Join(RestGnss()), {imu_path() + ":1: the gyro implies a turn rate of 20 rad/s", "degrees"});
}

TEST_F(I2navTest, GyroInDegreesIsRefusedAtTheFirstSustainedTurn) {
  // At rest first (the probe cannot tell degrees then), then a 10 deg/s corner written in degrees.
  std::vector<std::string> imu = RestImu(500);
  for (int k = 300; k < 500; ++k) imu[k] = Fixed(kT0 + 0.005 * k, 3) + " 0 0 " + Num(10.0 * 0.005) + " 0 0 -0.049";
  ExpectRefused(Join(imu), Join(RestGnss()),
                {imu_path() + ":301: the gyro turns faster than 5 rad/s (286 deg/s) for 1 s, to line 500",
                 "degrees"});
}

TEST_F(I2navTest, TimeBasesThatDoNotOverlapAreRefusedWithBothRanges) {
  ExpectRefused(Join(RestImu(100)), Join({GnssLine(1.7e9), GnssLine(1.7e9 + 1)}),
                {imu_path() + ": IMU times [357000.000, 357000.495] s and the GNSS times [1700000000.000, "
                              "1700000001.000] s of " + gnss_path() + " do not overlap",
                 "GPS seconds of week"});
}

TEST_F(I2navTest, TooLittleInputIsRefused) {
  ExpectRefused("", Join(RestGnss()), {imu_path() + ": no usable IMU lines in 0 lines"});
  ExpectRefused(RestImuLine(0) + "\n", Join(RestGnss()), {imu_path() + ": only one usable IMU line"});
  ExpectRefused(Join(RestImu(100)), "\n", {gnss_path() + ": no usable GNSS lines in 1 lines"});
  try {
    I2navInputs in{dir_ + "/missing.txt", gnss_path(), I2navImuData::kIncrements};
    ConvertI2nav(in, {}, dir_ + "/log.txt");
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), dir_ + "/missing.txt: cannot open: No such file or directory");
  }
}

}  // namespace
}  // namespace gins
