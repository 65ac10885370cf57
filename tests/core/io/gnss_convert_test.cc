// The merge of a GNSS file with the IMU/wheel records of a gins log or CSV files (core/io/gnss_convert.h):
// time order and ties, the --imu log's own GNSS and GVEL dropped and counted, ODOM and GVEL written so that
// they read back exactly, the refusals (time bases apart, no fixes), nothing written on failure, the summary.
#include "core/io/gnss_convert.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kT0 = 1440437439.0;  // GPS seconds: 2025-08-28 17:30:39 GPST

std::string Num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

// A gins log: IMU every 0.25 s from kT0 for 3 s, ODOM every 0.5 s, and a GNSS and GVEL of its own at kT0 + 1.
std::string ImuLog(double t0 = kT0) {
  std::string log = "# a logger's log\n";
  for (int k = 0; k <= 12; ++k) {
    const double t = t0 + 0.25 * k;
    log += "IMU " + Num(t) + " 0.001 -0.002 0.003 0.1 0.2 9.8\n";
    if (k % 2 == 0) log += "ODOM " + Num(t) + " 10 -11\n";
    if (k == 4) log += "GNSS " + Num(t) + " 30 120 10 0 0\nGVEL " + Num(t) + " 1 2 3\n";
  }
  return log;
}

// RTKLIB lines at kT0 + 0.75 and kT0 + 2.0 (the second at an IMU sample's time), with velocity columns.
std::string Pos() {
  return "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)"
         "  sdeu(m)  sdun(m) age(s)  ratio    vn(m/s)    ve(m/s)    vu(m/s)      sdvn     sdve     sdvu    sdvne"
         "    sdveu    sdvun\n"
         "2025/08/28 17:30:39.750   40.096716094 -105.147133192  1584.3679   1  15   0.0100   0.0200   0.0300  "
         "0 0 0 0.00 0.0  0.5 0.25 -0.125 0.01 0.02 0.03 0 0 0\n"
         "2025/08/28 17:30:41.000   40.096716094 -105.147133192  1584.3679   2  15   0.0100   0.0200   0.0300  "
         "0 0 0 0.00 0.0  0.5 0.25 -0.125 0.01 0.02 0.03 0 0 0\n";
}

struct Log {
  std::vector<LogRecord> records;
  std::string types;  // one letter per record: I O G V
};

Log ReadBack(const std::string& path) {
  InputOptions stop;
  stop.on_error = InputErrorPolicy::kStop;
  LogReader reader(path, stop);
  Log log;
  for (LogRecord r; reader.Next(&r);) {
    log.records.push_back(r);
    log.types += "IOGV"[r.type_index()];
  }
  return log;
}

class GnssConvert : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::MakeTempDir("gnss_convert"); }
  GnssConversion Convert(const std::string& format, const std::string& gnss, const std::string& imu,
                         const std::string& out = "log.txt", GnssConvertInputs in = {}) {
    in.format = format;
    in.gnss_path = dir_ + "/gnss";
    in.imu_path = dir_ + "/imu";
    test::WriteFile(in.gnss_path, gnss);
    test::WriteFile(in.imu_path, imu);
    return ConvertGnss(in, InputOptions{}, dir_ + "/" + out);
  }
  std::string ErrorOf(const std::string& format, const std::string& gnss, const std::string& imu,
                      GnssConvertInputs in = {}) {
    try {
      Convert(format, gnss, imu, "log.txt", in);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
  std::string dir_;
};

TEST_F(GnssConvert, MergesTheFixesIntoTheImuLogInTimeOrderAndDropsItsOwnGnss) {
  const GnssConversion c = Convert("rtklib-pos", Pos(), ImuLog());
  const Log log = ReadBack(dir_ + "/log.txt");
  // IMU at .00 .25 .50, the fix and its GVEL at .75 after the IMU sample there; at 2.0 IMU, ODOM, fix, GVEL.
  EXPECT_EQ(log.types, "IOIIOIGVIOIIOIIOGVIIOIIO");
  EXPECT_EQ(log.records[4].t(), kT0 + 0.5);
  EXPECT_EQ(log.records[6].get<GnssRecord>().t, kT0 + 0.75);
  EXPECT_EQ(log.records[6].get<GnssRecord>().sigma_enu, Vec3(0.02, 0.01, 0.03));
  EXPECT_EQ(log.records[7].get<GnssVelocityRecord>().v_enu, Vec3(0.25, 0.5, -0.125));
  EXPECT_EQ(log.records[7].get<GnssVelocityRecord>().sigma_enu, Vec3(0.02, 0.01, 0.03));
  EXPECT_EQ(log.records[1].get<WheelRecord>().left_pulses, 10.0);
  EXPECT_EQ(log.records[1].get<WheelRecord>().right_pulses, -11.0);
  EXPECT_EQ(c.imu.dropped_gnss, 1u);
  EXPECT_EQ(c.imu.dropped_gvel, 1u);
  EXPECT_EQ(c.written[0], 13u);
  EXPECT_EQ(c.written[1], 7u);
  EXPECT_EQ(c.written[2], 2u);
  EXPECT_EQ(c.written[3], 2u);
  EXPECT_EQ(c.t_first, kT0);
  EXPECT_EQ(c.t_last, kT0 + 3.0);
  const std::string summary = FormatGnssConversionSummary(c);
  EXPECT_NE(summary.find("gins convert: rtklib-pos -> " + dir_ +
                         "/log.txt (13 IMU, 7 ODOM, 2 GNSS, 2 GVEL records; "
                         "t 1440437439.000 .. 1440437442.000 s)"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("dropped its own 1 GNSS and 1 GVEL records"), std::string::npos) << summary;
  EXPECT_NE(summary.find("quality fix: 1\n    quality float: 1"), std::string::npos) << summary;
  EXPECT_NE(summary.find("time: GPST, no leap seconds"), std::string::npos) << summary;
}

TEST_F(GnssConvert, WritesGzipThatReadsBackTheSame) {
  Convert("rtklib-pos", Pos(), ImuLog(), "log.txt.gz");
  Convert("rtklib-pos", Pos(), ImuLog(), "log.txt");
  const Log gz = ReadBack(dir_ + "/log.txt.gz"), plain = ReadBack(dir_ + "/log.txt");
  EXPECT_EQ(gz.types, plain.types);
  EXPECT_NE(test::ReadFile(dir_ + "/log.txt.gz").substr(0, 2), "# ");
}

TEST_F(GnssConvert, RefusesImuAndGnssTimesThatDoNotOverlapNamingTheTimeScale) {
  const std::string error = ErrorOf("rtklib-pos", Pos(), ImuLog(kT0 + kGpsEpochUnix - 18.0));
  EXPECT_NE(error.find("IMU times [1756402221.000, 1756402224.000] s and the GNSS times [1440437439.750, "
                       "1440437441.000] s of "),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("do not overlap: one is Unix time, the other GPS time: --time-scale unix?"), std::string::npos)
      << error;
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/log.txt"));
}

TEST_F(GnssConvert, AFileWithoutUsableFixesIsRefused) {
  GnssConvertInputs in;
  in.options.min_quality = FixQuality::kFix;
  std::string pos = Pos();
  pos.replace(pos.find("   1  15"), 8, "   5  15");
  pos.replace(pos.find("   2  15"), 8, "   5  15");
  EXPECT_EQ(ErrorOf("rtklib-pos", pos, ImuLog(), in), dir_ +
                                                          "/gnss: no usable fixes in 3 lines (0 damaged, 2 "
                                                          "dropped by quality)");
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/log.txt"));
}

TEST_F(GnssConvert, DamageInTheImuLogFollowsThePolicyAndIsInTheSummary) {
  const GnssConversion c = Convert("rtklib-pos", Pos(), ImuLog() + "IMU 1440437443 abc 0 0 0 0 9.8\n");
  EXPECT_EQ(c.imu.file.skipped.at("bad_number"), 1u);
  const std::string summary = FormatGnssConversionSummary(c);
  EXPECT_NE(summary.find("skipped bad_number: 1 (first at line 24: "), std::string::npos) << summary;
}

TEST_F(GnssConvert, CsvImuAndWheelFilesMergeWithACsvGnssFile) {
  GnssConvertInputs in;
  in.gnss_columns = "t=1,lat=2,lon=3,h=4";
  in.imu_columns = "t=1,gx=2,gy=3,gz=4,ax=5,ay=6,az=7";
  in.wheel_path = dir_ + "/wheel.csv";
  in.wheel_columns = "t=1,left=2,right=3";
  test::WriteFile(in.wheel_path, "100.0,1,2\n100.1,3,4\n");
  const GnssConversion c = Convert("csv", "100.05,30,120,10\n",
                                   "100.0,0,0,0,0,0,9.8\n100.05,0,0,0,0,0,9.8\n100.1,0,0,0,0,0,9.8\n", "log.txt", in);
  EXPECT_EQ(ReadBack(dir_ + "/log.txt").types, "IOIGIO");
  EXPECT_EQ(c.imu.kind, "csv");
  EXPECT_NE(FormatGnssConversionSummary(c).find("  wheel csv " + in.wheel_path + ": 2 lines, 2 records (2 ODOM)"),
            std::string::npos)
      << FormatGnssConversionSummary(c);
}

}  // namespace
}  // namespace gins
