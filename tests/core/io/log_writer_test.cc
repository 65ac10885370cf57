// LogWriter (core/io/log_writer.h): what it writes reads back exactly through LogReader, plain or gzip, and
// nothing appears without Commit().
#include "core/io/log_writer.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/io/log_reader.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

void WriteSample(LogWriter* w) {
  w->Comment("made by a test\nsecond line");
  ImuSample s;
  s.t = 357000.0025;
  s.gyro = Vec3(0.1, -1.0 / 3.0, 2e-12);
  s.acc = Vec3(0.5, -0.25, 9.80665);
  w->Add({s});
  GnssRecord g;
  g.t = 357000.1;
  g.lat_deg = 30.4604325443;
  g.lon_deg = -114.4725046685;
  g.alt_m = 23.0;
  g.has_sigma = true;
  g.sigma_enu = Vec3(0.011, 0.008, 0.036);
  w->Add({g});
  g.t = 357000.2;
  g.has_sigma = false;
  g.heading_valid = true;
  g.heading_deg = 170.9;
  w->Add({g});
  w->Add({BarometerModule::Record{357000.3, 23.125, 0.0}});  // a measurement module's, by its own codec
  w->Add({BarometerModule::Record{357000.4, -7.5, 0.25}});
}

TEST(LogWriterTest, RecordsReadBackExactlyPlainAndGzip) {
  const std::string dir = test::MakeTempDir("log_writer");
  for (const std::string name : {"log.txt", "log.txt.gz"}) {
    SCOPED_TRACE(name);
    const std::string path = dir + "/" + name;
    LogWriter w(path);
    WriteSample(&w);
    w.Commit();
    EXPECT_EQ(w.records(), 5u);
    InputOptions stop;
    stop.on_error = InputErrorPolicy::kStop;
    LogReader r(path, stop);
    LogRecord rec;
    ASSERT_TRUE(r.Next(&rec));
    EXPECT_EQ(rec.line, 2u);  // the comment is one line
    EXPECT_EQ(rec.get<ImuSample>().t, 357000.0025);
    EXPECT_EQ(rec.get<ImuSample>().gyro, Vec3(0.1, -1.0 / 3.0, 2e-12));
    EXPECT_EQ(rec.get<ImuSample>().acc, Vec3(0.5, -0.25, 9.80665));
    ASSERT_TRUE(r.Next(&rec));
    EXPECT_EQ(rec.get<GnssRecord>().lon_deg, -114.4725046685);
    EXPECT_FALSE(rec.get<GnssRecord>().heading_valid);
    EXPECT_EQ(rec.get<GnssRecord>().sigma_enu, Vec3(0.011, 0.008, 0.036));
    ASSERT_TRUE(r.Next(&rec));
    EXPECT_TRUE(rec.get<GnssRecord>().heading_valid);
    EXPECT_EQ(rec.get<GnssRecord>().heading_deg, 170.9);
    EXPECT_FALSE(rec.get<GnssRecord>().has_sigma);
    ASSERT_TRUE(r.Next(&rec));
    EXPECT_EQ(rec.get<BarometerModule::Record>().alt_m, 23.125);
    EXPECT_EQ(rec.get<BarometerModule::Record>().sigma_m, 0.0);
    ASSERT_TRUE(r.Next(&rec));
    EXPECT_EQ(rec.get<BarometerModule::Record>().t, 357000.4);
    EXPECT_EQ(rec.get<BarometerModule::Record>().alt_m, -7.5);
    EXPECT_EQ(rec.get<BarometerModule::Record>().sigma_m, 0.25);
    EXPECT_FALSE(r.Next(&rec));
  }
  EXPECT_EQ(test::ReadFile(dir + "/log.txt").rfind("# made by a test second line\nIMU 357000.0025 0.1 ", 0), 0u);
}

TEST(LogWriterTest, NothingAppearsWithoutCommit) {
  const std::string dir = test::MakeTempDir("log_writer");
  {
    LogWriter w(dir + "/log.txt.gz");
    WriteSample(&w);
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

}  // namespace
}  // namespace gins
