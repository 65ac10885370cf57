// CSV through a column map (core/io/csv_columns.h): the map's syntax and its refusals, units, signs for
// axes, header names, exact integer time stamps, and damage by line when a column the map names is not there.
#include "core/io/csv_columns.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

struct Read {
  std::vector<LogRecord> records;
  ConvertedFile file;
};

class Csv : public ::testing::Test {
 protected:
  void SetUp() override { path_ = test::MakeTempDir("csv") + "/data.csv"; }
  Read ReadText(const std::string& text, const std::string& map, CsvKind kind, const InputOptions& options = {}) {
    test::WriteFile(path_, text);
    const std::unique_ptr<RecordSource> source = OpenCsv(path_, ParseColumnMap(map, kind, "--map"), options);
    Read r;
    LogRecord record;
    while (source->Next(&record)) r.records.push_back(record);
    r.file = source->file();
    return r;
  }
  std::string ErrorOf(const std::string& text, const std::string& map, CsvKind kind, bool stop) {
    InputOptions options;
    if (stop) options.on_error = InputErrorPolicy::kStop;
    try {
      ReadText(text, map, kind, options);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
  std::string path_;
};

std::string MapError(const std::string& map, CsvKind kind) {
  try {
    ParseColumnMap(map, kind, "--gnss-columns");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CsvColumnMap, RefusesUnknownKeysUnitsRepeatsAndIncompleteGroups) {
  EXPECT_EQ(MapError("t=1,lat=2,lon=3", CsvKind::kGnss), "--gnss-columns: 'h' is required (in \"t=1,lat=2,lon=3\")");
  EXPECT_NE(MapError("t=1,lat=2,lon=3,h=4,alt=5", CsvKind::kGnss).find("unknown key 'alt'; the keys are t lat lon h"),
            std::string::npos);
  EXPECT_NE(MapError("t=1:min,lat=2,lon=3,h=4", CsvKind::kGnss).find("unit 'min' of 't' is not s | ms | us | ns"),
            std::string::npos);
  EXPECT_NE(MapError("t=1,lat=2,lat=3,h=4", CsvKind::kGnss).find("'lat' given twice"), std::string::npos);
  EXPECT_NE(MapError("t=1,lat=2,lon=3,h=4,se=5,sn=6", CsvKind::kGnss).find("se..su: all three or none"),
            std::string::npos);
  EXPECT_NE(MapError("t=0,lat=2,lon=3,h=4", CsvKind::kGnss).find("columns count from 1"), std::string::npos);
  EXPECT_NE(MapError("t=-1,lat=2,lon=3,h=4", CsvKind::kGnss).find("the time cannot be negated"), std::string::npos);
  EXPECT_NE(MapError("t=1,gx=2", CsvKind::kImu).find("'gy' is required"), std::string::npos);
  EXPECT_EQ(MapError("t=1, lat=2:rad, lon=3:rad ,h=4", CsvKind::kGnss), "no error");
}

TEST_F(Csv, ImuColumnsTakeUnitsSignsAndExactNanosecondStamps) {
  // FRD gyro in deg/s and accelerometer in g, nanoseconds since the epoch: FLU rad/s and m/s² out.
  const Read r = ReadText("1700000000123456789,1.0,2.0,-3.0,0.01,0.02,-1.0\n",
                          "t=1:ns,gx=2:deg/s,gy=-3:deg/s,gz=-4:deg/s,ax=5:g,ay=-6:g,az=-7:g", CsvKind::kImu);
  ASSERT_EQ(r.records.size(), 1u);
  const ImuSample& s = r.records[0].get<ImuSample>();
  EXPECT_EQ(s.t, 1700000000.0 + 0.123456789);
  EXPECT_EQ(s.gyro, Vec3(1.0 * kDegToRad, -2.0 * kDegToRad, 3.0 * kDegToRad));
  EXPECT_EQ(s.acc, Vec3(0.01 * 9.80665, -0.02 * 9.80665, 1.0 * 9.80665));
}

TEST_F(Csv, GnssColumnsByHeaderNameWithSigmaHeadingAndVelocity) {
  const Read r = ReadText(
      "time;latitude;longitude;height;s_e;s_n;s_u;yaw;v_e;v_n;v_u\n"
      "1700000000.5;0.5;2.0;12.5;0.02;0.03;0.05;;1.0;2.0;0.1\n"
      "1700000001.5;0.5;2.0;12.5;0.02;0.03;0.05;90;1.0;2.0;0.1\n",
      "t=time,lat=latitude:rad,lon=longitude:rad,h=height,se=s_e,sn=s_n,su=s_u,heading=yaw,ve=v_e,vn=v_n,vu=v_u",
      CsvKind::kGnss);
  ASSERT_EQ(r.records.size(), 4u);
  const GnssRecord& g = r.records[0].get<GnssRecord>();
  EXPECT_EQ(g.t, 1700000000.5);
  EXPECT_EQ(g.lat_deg, 0.5 * kRadToDeg);
  EXPECT_EQ(g.lon_deg, 2.0 * kRadToDeg);
  EXPECT_EQ(g.sigma_enu, Vec3(0.02, 0.03, 0.05));
  EXPECT_FALSE(g.heading_valid);  // an empty heading field: no heading at this fix
  EXPECT_TRUE(r.records[2].get<GnssRecord>().heading_valid);
  EXPECT_EQ(r.records[2].get<GnssRecord>().heading_deg, 90.0);
  EXPECT_TRUE(r.records[1].is<GnssVelocityRecord>());
  EXPECT_EQ(r.records[1].get<GnssVelocityRecord>().v_enu, Vec3(1.0, 2.0, 0.1));
  EXPECT_FALSE(r.records[1].get<GnssVelocityRecord>().has_sigma);
}

TEST_F(Csv, WheelColumnsBecomeOdomRecords) {
  const Read r = ReadText("t,l,r\n10.0, 5, 6\n10.1, -5, 7\n", "t=1,left=2,right=3", CsvKind::kWheel);
  ASSERT_EQ(r.records.size(), 2u);
  EXPECT_TRUE(r.records[1].is<WheelRecord>());
  EXPECT_EQ(r.records[1].get<WheelRecord>().left_pulses, -5.0);
  EXPECT_EQ(r.records[1].get<WheelRecord>().right_pulses, 7.0);
}

TEST_F(Csv, AColumnTheMapNamesThatIsNotThereIsDamageNamedByLine) {
  const std::string text =
      "1.0,30.0,120.0,10.0,0.1\n2.0,30.0,120.0,10.0,0.1,0.1,0.2\n3.0,30.0,120.0,10.0,0.1,0.1,0.2\n";
  const std::string map = "t=1,lat=2,lon=3,h=4,se=5,sn=6,su=7";
  const Read r = ReadText(text, map, CsvKind::kGnss);
  ASSERT_EQ(r.records.size(), 2u);
  EXPECT_EQ(r.file.skipped.at("missing_fields"), 1u);
  EXPECT_EQ(r.file.issues[0].line, 1u);
  EXPECT_EQ(ErrorOf(text, map, CsvKind::kGnss, true),
            path_ + ":1: missing_fields: the line has 5 columns; --map puts su in column 7");
}

TEST_F(Csv, AHeaderNameTheHeaderLacksRefusesTheFile) {
  EXPECT_EQ(ErrorOf("t,lat,lon,alt\n1,30,120,10\n", "t=t,lat=lat,lon=lon,h=h", CsvKind::kGnss, false),
            path_ + ":1: --map names column 'h' (h), which is not in the header: t, lat, lon, alt");
  EXPECT_EQ(ErrorOf("1,30,120,10\n", "t=t,lat=2,lon=3,h=4", CsvKind::kGnss, false),
            path_ + ":1: --map names column 't' (t) but the file has no header line");
}

TEST_F(Csv, BadOrEmptyFieldsAndTimesThatGoBackwardsAreDamage) {
  const Read r =
      ReadText("1.0 30 120 10\n2.0 30 x 10\n0.5 30 120 10\n3.0 30 120 10\n", "t=1,lat=2,lon=3,h=4", CsvKind::kGnss);
  ASSERT_EQ(r.records.size(), 2u);
  EXPECT_EQ(r.file.skipped.at("bad_number"), 1u);
  EXPECT_EQ(r.file.skipped.at("time_backwards"), 1u);
  EXPECT_EQ(r.file.issues[0].detail, "column 3 (lon) 'x' is not a number");
  EXPECT_EQ(ErrorOf("1.0 30 120 10\n0.5 30 120 10\n", "t=1,lat=2,lon=3,h=4", CsvKind::kGnss, true),
            path_ + ":2: time_backwards: t = 0.500000 s is before the previous line's 1.000000 s");
}

}  // namespace
}  // namespace gins
