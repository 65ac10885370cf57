// RTKLIB solution files (core/io/rtklib_pos.cc): the time forms and systems, the position forms (degrees,
// d m s, ECEF with its σ rotated into ENU), velocity columns, the quality policy, and damage by line.
#include <gtest/gtest.h>

#include <GeographicLib/Geocentric.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "core/io/gnss_formats.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kWalkGps = 1440437439.75;  // 2025-08-28 17:30:39.75 GPST

constexpr const char kLlhHeader[] =
    "% program   : RTKLIB ver.2.4.3\n"
    "% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)\n";
constexpr const char kGpstColumns[] =
    "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)"
    "  sdeu(m)  sdun(m) age(s)  ratio\n";

// A solution line of the llh layout at second s after 17:30:39 GPST with quality q.
std::string Line(int s, int q = 5, const char* time = nullptr) {
  char buf[256];
  char t[64];
  std::snprintf(t, sizeof(t), "2025/08/28 17:30:%02d.750", 39 + s);
  std::snprintf(buf, sizeof(buf),
                "%s   40.096716094 -105.147133192  1584.3679   %d  15   2.0453   1.7674   4.7139  -0.6069  -0.5974  "
                "-1.3199   0.00    0.0\n",
                time != nullptr ? time : t, q);
  return buf;
}

struct Read {
  std::vector<LogRecord> records;
  ConvertedFile file;
  GnssFileStats stats;
};

class RtklibPos : public ::testing::Test {
 protected:
  void SetUp() override { path_ = test::MakeTempDir("rtklib_pos") + "/sol.pos"; }
  Read ReadText(const std::string& text, const InputOptions& options = {}, const GnssFormatOptions& format = {}) {
    test::WriteFile(path_, text);
    const std::unique_ptr<RecordSource> source = OpenRtklibPos(path_, options, format);
    Read r;
    LogRecord record;
    while (source->Next(&record)) r.records.push_back(record);
    r.file = source->file();
    r.stats = source->stats();
    return r;
  }
  std::string ErrorOf(const std::string& text, const InputOptions& options = {}) {
    try {
      ReadText(text, options);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
  static InputOptions Stop() {
    InputOptions o;
    o.on_error = InputErrorPolicy::kStop;
    return o;
  }
  std::string path_;
};

TEST_F(RtklibPos, ReadsGpstCalendarLinesAsGnssRecordsWithSigmaEastNorthUp) {
  const Read r = ReadText(std::string(kLlhHeader) + kGpstColumns + Line(0) + Line(1));
  ASSERT_EQ(r.records.size(), 2u);
  const GnssRecord& g = r.records[0].get<GnssRecord>();
  EXPECT_TRUE(r.records[0].is<GnssRecord>());
  EXPECT_EQ(r.records[0].line, 4u);
  EXPECT_EQ(g.t, kWalkGps);
  EXPECT_EQ(g.lat_deg, 40.096716094);
  EXPECT_EQ(g.lon_deg, -105.147133192);
  EXPECT_EQ(g.alt_m, 1584.3679);
  EXPECT_FALSE(g.heading_valid);
  ASSERT_TRUE(g.has_sigma);
  EXPECT_EQ(g.sigma_enu, Vec3(1.7674, 2.0453, 4.7139));  // sde, sdn, sdu
  EXPECT_EQ(r.records[1].get<GnssRecord>().t, kWalkGps + 1.0);
  EXPECT_EQ(r.stats.qualities.at("single"), 2u);
  EXPECT_EQ(r.stats.leap_seconds.at(0), 2u);
  EXPECT_EQ(r.file.total_skipped(), 0u);
}

TEST_F(RtklibPos, ReadsUtcCalendarTimesIntoGpsSeconds) {
  std::string columns = kGpstColumns;
  columns.replace(columns.find("GPST"), 4, "UTC ");
  const Read r = ReadText(std::string(kLlhHeader) + columns + Line(0, 5, "2025/08/28 17:30:21.750"));
  ASSERT_EQ(r.records.size(), 1u);
  EXPECT_EQ(r.records[0].get<GnssRecord>().t, kWalkGps);
  EXPECT_EQ(r.stats.leap_seconds.at(18), 1u);
  GnssFormatOptions unix_log;
  unix_log.time_scale = LogTimeScale::kUnixUtc;
  const Read u = ReadText(std::string(kLlhHeader) + columns + Line(0, 5, "2025/08/28 17:30:21.750"), {}, unix_log);
  EXPECT_EQ(u.records[0].get<GnssRecord>().t, kWalkGps + kGpsEpochUnix - 18.0);
}

TEST_F(RtklibPos, ReadsWeekSecondsTimesWithCommaSeparatedFields) {
  // out-timesys=utc, out-timeform=tow, out-fieldsep=, as RTKLIB writes them: UTC weeks and seconds.
  const Read r =
      ReadText(std::string(kLlhHeader) +
               "%  UTC         , latitude(deg),longitude(deg), height(m),  Q, ns,  sdn(m),  sde(m),  sdu(m), "
               "sdne(m), sdeu(m), sdun(m),age(s), ratio\n"
               "2381,408621.750,  40.096716094,-105.147133192, 1584.3679,  1, 15,  0.0100,  0.0120,  "
               "0.0300, -0.0010, -0.0010, -0.0010,  0.00,   0.0\n");
  ASSERT_EQ(r.records.size(), 1u);
  EXPECT_EQ(r.records[0].get<GnssRecord>().t, kWalkGps);
  EXPECT_EQ(r.records[0].get<GnssRecord>().sigma_enu, Vec3(0.012, 0.01, 0.03));
  EXPECT_EQ(r.stats.qualities.at("fix"), 1u);
}

TEST_F(RtklibPos, JstTimesAreUtcPlusNineHours) {
  std::string columns = kGpstColumns;
  columns.replace(columns.find("GPST"), 4, "JST ");
  const Read r = ReadText(std::string(kLlhHeader) + columns + Line(0, 5, "2025/08/29 02:30:21.750"));
  ASSERT_EQ(r.records.size(), 1u);
  EXPECT_EQ(r.records[0].get<GnssRecord>().t, kWalkGps);
}

TEST_F(RtklibPos, RotatesEcefSigmaIntoEnuAtThePoint) {
  // A covariance diag(1, 4, 9) m² in ENU at the point, written as RTKLIB's ECEF σ (signed square roots).
  const double lat = 40.0967161, lon = -105.1471332, h = 1584.37;
  double x, y, z;
  std::vector<double> M(9);
  GeographicLib::Geocentric::WGS84().Forward(lat, lon, h, x, y, z, M);
  const Mat3 R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(M.data());
  const Mat3 C = R * Vec3(1.0, 4.0, 9.0).asDiagonal() * R.transpose();
  auto sd = [](double c) { return std::copysign(std::sqrt(std::abs(c)), c); };
  const Vec3 v = R * Vec3(1.0, 2.0, 0.5);  // 1 m/s east, 2 north, 0.5 up
  char line[512];
  std::snprintf(line, sizeof(line),
                "2025/08/28 17:30:39.750 %.5f %.5f %.5f 5 15 %.7f %.7f %.7f %.7f %.7f %.7f 0.0 0.0 %.9f %.9f %.9f\n", x,
                y, z, sd(C(0, 0)), sd(C(1, 1)), sd(C(2, 2)), sd(C(0, 1)), sd(C(1, 2)), sd(C(2, 0)), v.x(), v.y(),
                v.z());
  const Read r = ReadText(
      "% (x/y/z-ecef=WGS84,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)\n"
      "%  GPST                      x-ecef(m)      y-ecef(m)      z-ecef(m)   Q  ns   sdx(m)   sdy(m)   sdz(m)  "
      "sdxy(m)  sdyz(m)  sdzx(m) age(s)  ratio    vx(m/s)    vy(m/s)    vz(m/s)\n" +
      std::string(line));
  ASSERT_EQ(r.records.size(), 2u);
  const GnssVelocityRecord& velocity = r.records[1].get<GnssVelocityRecord>();
  EXPECT_TRUE(velocity.v_enu.isApprox(Vec3(1.0, 2.0, 0.5), 1e-8)) << velocity.v_enu.transpose();
  EXPECT_FALSE(velocity.has_sigma);
  const GnssRecord& g = r.records[0].get<GnssRecord>();
  EXPECT_NEAR(g.lat_deg, lat, 1e-10);
  EXPECT_NEAR(g.lon_deg, lon, 1e-10);
  EXPECT_NEAR(g.alt_m, h, 1e-4);
  EXPECT_NEAR(g.sigma_enu.x(), 1.0, 1e-5);
  EXPECT_NEAR(g.sigma_enu.y(), 2.0, 1e-5);
  EXPECT_NEAR(g.sigma_enu.z(), 3.0, 1e-5);
}

TEST_F(RtklibPos, ReadsDegreesMinutesSecondsPositions) {
  const Read r = ReadText(
      std::string(kLlhHeader) +
      "%  GPST                    latitude(d'\")   longitude(d'\")  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  "
      "sdne(m)  sdeu(m)  sdue(m) age(s)  ratio\n"
      "2025/08/28 17:30:39.750   40 05 48.17794 -105 08 49.67949  1584.3679   5  15   2.0453   1.7674   4.7139  "
      "-0.6069  -0.5974  -1.3199   0.00    0.0\n"
      "2025/08/28 17:30:40.750   -0 30 00.00000 -0 15 00.00000  1584.3679   5  15   2.0453   1.7674   4.7139  "
      "-0.6069  -0.5974  -1.3199   0.00    0.0\n");
  ASSERT_EQ(r.records.size(), 2u);
  EXPECT_NEAR(r.records[0].get<GnssRecord>().lat_deg, 40.096716094, 1e-9);
  EXPECT_NEAR(r.records[0].get<GnssRecord>().lon_deg, -105.147133192, 1e-9);
  EXPECT_EQ(r.records[1].get<GnssRecord>().lat_deg, -0.5);  // the sign of "-0" kept
  EXPECT_EQ(r.records[1].get<GnssRecord>().lon_deg, -0.25);
  EXPECT_EQ(r.records[0].get<GnssRecord>().sigma_enu, Vec3(1.7674, 2.0453, 4.7139));
}

TEST_F(RtklibPos, VelocityColumnsBecomeGvelRecordsAfterTheirFix) {
  const Read r =
      ReadText(std::string(kLlhHeader) + std::string(kGpstColumns).substr(0, std::string(kGpstColumns).size() - 1) +
               "    vn(m/s)    ve(m/s)    vu(m/s)      sdvn     sdve     sdvu    sdvne    sdveu    sdvun\n" +
               Line(0).substr(0, Line(0).size() - 1) +
               "   -0.01042    0.01309    0.01111   0.11605  0.09911  0.26458  0.01401 -0.03757 -0.07552\n");
  ASSERT_EQ(r.records.size(), 2u);
  EXPECT_TRUE(r.records[1].is<GnssVelocityRecord>());
  const GnssVelocityRecord& v = r.records[1].get<GnssVelocityRecord>();
  EXPECT_EQ(v.t, kWalkGps);
  EXPECT_EQ(v.v_enu, Vec3(0.01309, -0.01042, 0.01111));
  ASSERT_TRUE(v.has_sigma);
  EXPECT_EQ(v.sigma_enu, Vec3(0.09911, 0.11605, 0.26458));
  EXPECT_EQ(CountOf<GnssVelocityRecord>(r.stats.records), 1u);
}

TEST_F(RtklibPos, KeepsEveryQualityWithItsSigmaAndDropsWhatIsBelowMinQuality) {
  std::string text = std::string(kLlhHeader) + kGpstColumns;
  for (int q = 1; q <= 7; ++q) text += Line(q, q);
  const Read all = ReadText(text);
  ASSERT_EQ(all.records.size(), 6u);  // Q 7, the solver's dead reckoning, is not a measurement
  EXPECT_EQ(all.stats.dropped.at("dead reckoning (Q 7)"), 1u);
  for (const char* q : {"fix", "float", "sbas", "dgps", "single", "ppp"}) EXPECT_EQ(all.stats.qualities.at(q), 1u) << q;
  for (const LogRecord& r : all.records) EXPECT_EQ(r.get<GnssRecord>().sigma_enu, Vec3(1.7674, 2.0453, 4.7139));
  GnssFormatOptions floats;
  floats.min_quality = FixQuality::kFloat;
  const Read best = ReadText(text, {}, floats);
  ASSERT_EQ(best.records.size(), 2u);  // Q 1 and 2
  EXPECT_EQ(best.records[0].get<GnssRecord>().t, kWalkGps + 1.0);
  EXPECT_EQ(best.records[1].get<GnssRecord>().t, kWalkGps + 2.0);
  EXPECT_EQ(best.stats.dropped.at("Q single (below --min-quality float)"), 1u);
  EXPECT_EQ(best.stats.dropped.at("Q ppp (below --min-quality float)"), 1u);
  EXPECT_EQ(best.file.total_skipped(), 0u);
}

TEST_F(RtklibPos, AnUnknownQualityFlagIsDamageNamedByLine) {
  const std::string text = std::string(kLlhHeader) + kGpstColumns + Line(0) + Line(1, 8) + Line(2);
  const Read r = ReadText(text);
  ASSERT_EQ(r.records.size(), 2u);
  EXPECT_EQ(r.file.skipped.at("unknown_quality"), 1u);
  ASSERT_EQ(r.file.issues.size(), 1u);
  EXPECT_EQ(r.file.issues[0].line, 5u);
  EXPECT_EQ(ErrorOf(text, Stop()).rfind(path_ + ":5: unknown_quality: column 6 (Q) = '8'", 0), 0u)
      << ErrorOf(text, Stop());
}

TEST_F(RtklibPos, TimesThatGoBackwardsOrRepeatAreDamage) {
  const std::string text = std::string(kLlhHeader) + kGpstColumns + Line(2) + Line(1) + Line(2) + Line(3);
  const Read r = ReadText(text);
  ASSERT_EQ(r.records.size(), 2u);
  EXPECT_EQ(r.file.skipped.at("time_backwards"), 1u);
  EXPECT_EQ(r.file.skipped.at("duplicate"), 1u);
  EXPECT_EQ(ErrorOf(text, Stop()).rfind(path_ + ":5: time_backwards: t = 1440437440.750 s is before", 0), 0u)
      << ErrorOf(text, Stop());
}

TEST_F(RtklibPos, ACutLineIsTruncatedAtTheEndAndMissingFieldsInside) {
  const std::string cut = Line(3).substr(0, 60);  // no newline: the file ends mid-line
  const Read r =
      ReadText(std::string(kLlhHeader) + kGpstColumns + Line(0) + Line(1).substr(0, 50) + "\n" + Line(2) + cut);
  ASSERT_EQ(r.records.size(), 2u);
  EXPECT_EQ(r.file.skipped.at("missing_fields"), 1u);
  EXPECT_EQ(r.file.skipped.at("truncated"), 1u);
  EXPECT_EQ(r.file.issues[0].line, 5u);
  EXPECT_EQ(r.file.issues[1].line, 7u);
  EXPECT_EQ(ErrorOf(std::string(kLlhHeader) + kGpstColumns + cut, Stop()),
            path_ +
                ":4: truncated: last line has no newline and is damaged: missing_fields: 5 columns, the layout "
                "needs 15 (RTKLIB solution, GPST, lat/lon/height, σ sdn sde sdu)");
}

TEST_F(RtklibPos, BadNumbersAndTimesAreDamage) {
  std::string bad_number = Line(1);
  bad_number.replace(bad_number.find("40.096716094"), 12, "40.0967x6094");
  const Read r =
      ReadText(std::string(kLlhHeader) + kGpstColumns + Line(0, 5, "2025/02/29 00:00:00.000") + bad_number + Line(2));
  ASSERT_EQ(r.records.size(), 1u);
  EXPECT_EQ(r.file.skipped.at("bad_time"), 1u);
  EXPECT_EQ(r.file.skipped.at("bad_number"), 1u);
}

TEST_F(RtklibPos, RefusesHeightsAboveTheGeoidAndBaselines) {
  std::string geoid = kLlhHeader;
  geoid.replace(geoid.find("ellipsoidal"), 11, "geodetic");
  EXPECT_NE(ErrorOf(geoid + kGpstColumns + Line(0)).find(path_ + ":2: heights above the geoid"), std::string::npos);
  EXPECT_NE(ErrorOf("%  GPST  e-baseline(m)  n-baseline(m)  u-baseline(m)   Q  ns\n").find(":1: e/n/u baselines"),
            std::string::npos);
}

TEST_F(RtklibPos, WithoutAHeaderTakesRtklibsDefaultColumnsAndSaysSo) {
  const Read r = ReadText(Line(0) + Line(1));
  ASSERT_EQ(r.records.size(), 2u);
  EXPECT_EQ(r.records[0].get<GnssRecord>().lat_deg, 40.096716094);
  EXPECT_EQ(r.records[0].get<GnssRecord>().sigma_enu, Vec3(1.7674, 2.0453, 4.7139));
  EXPECT_EQ(r.file.warnings.at("no_header"), 1u);
}

}  // namespace
}  // namespace gins
