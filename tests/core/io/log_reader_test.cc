#include "core/io/log_reader.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

using namespace std::string_literals;  // "..."s keeps embedded NUL bytes

std::string Imu(const std::string& t) { return "IMU " + t + " 0.01 -0.02 0.03 0.1 -0.2 9.8"; }

void WriteGzip(const std::string& path, const std::string& text, const char* mode = "wb") {
  gzFile f = gzopen(path.c_str(), mode);
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(gzwrite(f, text.data(), static_cast<unsigned>(text.size())), static_cast<int>(text.size()));
  ASSERT_EQ(gzclose(f), Z_OK);
}

struct ReadResult {
  std::vector<LogRecord> records;
  ReadStats stats;
};

ReadResult ReadAll(const std::string& path, const InputOptions& options = {}) {
  LogReader reader(path, options);
  ReadResult result;
  LogRecord record;
  while (reader.Next(&record)) result.records.push_back(record);
  result.stats = reader.stats();
  return result;
}

class LogReaderTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::MakeTempDir("log_reader"); }
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = dir_ + "/" + name;
    test::WriteFile(path, text);
    return path;
  }
  std::string dir_;
};

TEST_F(LogReaderTest, ReadsAllTypesWithValuesAndLineNumbers) {
  const std::string path = Write("log.txt",
                                 "IMU 1.0 0.01 -0.02 0.03 0.1 -0.2 9.8\n"
                                 "ODOM 1.0 10 -12\n"
                                 "GNSS 1.0 31.5 120.4 10.5 170.9 1 0.02 0.03 0.05\n"
                                 "GNSS 1.1 -31.5 -120.4 -10.5 -10 1\n"
                                 "GNSS 1.2 31.5 120.4 10.5 999 0\n");
  const ReadResult r = ReadAll(path);
  ASSERT_EQ(r.records.size(), 5u);
  const LogRecord& imu = r.records[0];
  EXPECT_TRUE(imu.is<ImuSample>());
  EXPECT_EQ(imu.line, 1u);
  EXPECT_EQ(imu.t(), 1.0);
  EXPECT_EQ(imu.get<ImuSample>().gyro, Vec3(0.01, -0.02, 0.03));
  EXPECT_EQ(imu.get<ImuSample>().acc, Vec3(0.1, -0.2, 9.8));
  const LogRecord& wheel = r.records[1];
  EXPECT_TRUE(wheel.is<WheelRecord>());
  EXPECT_EQ(wheel.line, 2u);
  EXPECT_EQ(wheel.get<WheelRecord>().left_pulses, 10.0);
  EXPECT_EQ(wheel.get<WheelRecord>().right_pulses, -12.0);
  const GnssRecord& g = r.records[2].get<GnssRecord>();
  EXPECT_TRUE(r.records[2].is<GnssRecord>());
  EXPECT_EQ(g.lat_deg, 31.5);
  EXPECT_EQ(g.lon_deg, 120.4);
  EXPECT_EQ(g.alt_m, 10.5);
  EXPECT_EQ(g.heading_deg, 170.9);
  EXPECT_TRUE(g.heading_valid);
  EXPECT_TRUE(g.has_sigma);
  EXPECT_EQ(g.sigma_enu, Vec3(0.02, 0.03, 0.05));
  const GnssRecord& g2 = r.records[3].get<GnssRecord>();
  EXPECT_EQ(g2.t, 1.1);
  EXPECT_FALSE(g2.has_sigma);
  EXPECT_DOUBLE_EQ(g2.heading_deg, 350.0);  // -10 normalised into [0, 360)
  EXPECT_EQ(g2.lat_deg, -31.5);
  // An invalid heading is a placeholder: any value is accepted and not passed on.
  const GnssRecord& g3 = r.records[4].get<GnssRecord>();
  EXPECT_FALSE(g3.heading_valid);
  EXPECT_EQ(g3.heading_deg, 0.0);
  EXPECT_EQ(r.stats.lines, 5u);
  EXPECT_EQ(CountOf<ImuSample>(r.stats.records), 1u);
  EXPECT_EQ(CountOf<WheelRecord>(r.stats.records), 1u);
  EXPECT_EQ(CountOf<GnssRecord>(r.stats.records), 3u);
  EXPECT_EQ(r.stats.total_skipped(), 0u);
  EXPECT_TRUE(r.stats.examples.empty());
}

TEST_F(LogReaderTest, GnssVelocityWithAndWithoutSigma) {
  const ReadResult r = ReadAll(Write("log.txt", Imu("1.0") + "\nGVEL 1.0 3.5 -1.25 0.5\nGVEL 2.0 1 2 3 0.1 0.2 0.3\n"));
  ASSERT_EQ(r.records.size(), 3u);
  EXPECT_EQ(CountOf<GnssVelocityRecord>(r.stats.records), 2u);
  ASSERT_TRUE(r.records[1].is<GnssVelocityRecord>());
  EXPECT_EQ(r.records[1].get<GnssVelocityRecord>().t, 1.0);
  EXPECT_EQ(r.records[1].get<GnssVelocityRecord>().v_enu, Vec3(3.5, -1.25, 0.5));
  EXPECT_FALSE(r.records[1].get<GnssVelocityRecord>().has_sigma);
  EXPECT_TRUE(r.records[2].get<GnssVelocityRecord>().has_sigma);
  EXPECT_EQ(r.records[2].get<GnssVelocityRecord>().sigma_enu, Vec3(0.1, 0.2, 0.3));
  EXPECT_EQ(r.records[2].line, 3u);
}

TEST_F(LogReaderTest, CommentsBlankLinesCrlfTabsAndWhitespace) {
  const std::string path = Write("log.txt",
                                 "# gins log\r\n"
                                 "\r\n"
                                 "   \t \n"
                                 "  IMU 1.0 0.01 -0.02 0.03 0.1 -0.2 9.8   # trailing comment\r\n"
                                 "\tODOM\t1.0\t10\t-12\t\r\n"
                                 "#IMU 0.5 0 0 0 0 0 9.8\n"
                                 "GNSS  1.0  31.5 120.4 10.5 170.9 1#no space before the comment\n"
                                 "\r\n"
                                 "\xEF\xBB\xBFIMU 2.0 0 0 0 0 0 9.8\n");
  const ReadResult r = ReadAll(path);
  ASSERT_EQ(r.records.size(), 3u);
  EXPECT_EQ(r.records[0].line, 4u);
  EXPECT_EQ(r.records[0].get<ImuSample>().acc.z(), 9.8);
  EXPECT_EQ(r.records[1].line, 5u);
  EXPECT_EQ(r.records[1].get<WheelRecord>().right_pulses, -12.0);
  EXPECT_EQ(r.records[2].line, 7u);
  EXPECT_TRUE(r.records[2].get<GnssRecord>().heading_valid);
  EXPECT_EQ(r.stats.lines, 9u);
  // A BOM is only skipped at the start of the file; elsewhere it is an unknown record type.
  EXPECT_EQ(r.stats.skipped.at("unknown_type"), 1u);
  EXPECT_EQ(r.stats.total_skipped(), 1u);
}

TEST_F(LogReaderTest, Utf8BomAtStartIsSkipped) {
  const ReadResult r = ReadAll(Write("log.txt", "\xEF\xBB\xBF" + Imu("1.0") + "\n"));
  ASSERT_EQ(r.records.size(), 1u);
  EXPECT_EQ(r.stats.total_skipped(), 0u);
}

TEST_F(LogReaderTest, NumberSyntaxAcceptedLikeStrtod) {
  const ReadResult r = ReadAll(Write("log.txt",
                                     "IMU +1.5 1e-400 .5 -0. 1E1 -2.5e+1 35\n"
                                     "GNSS 2 90 -180 -999.9 360 1\n"
                                     "GNSS 3 -90 180 99999.9 -360 1\n"
                                     "IMU 3 35 -35 0 200 -200 0\n"));
  ASSERT_EQ(r.records.size(), 4u) << (r.stats.examples.empty() ? "" : r.stats.examples[0].detail);
  EXPECT_EQ(r.records[0].get<ImuSample>().t, 1.5);
  EXPECT_EQ(r.records[0].get<ImuSample>().gyro, Vec3(0.0, 0.5, -0.0));
  EXPECT_EQ(r.records[0].get<ImuSample>().acc, Vec3(10.0, -25.0, 35.0));
  EXPECT_EQ(r.records[1].get<GnssRecord>().heading_deg, 0.0);
  EXPECT_EQ(r.records[2].get<GnssRecord>().heading_deg, 0.0);
}

TEST_F(LogReaderTest, GzipDetectedByMagicBytesNotByName) {
  const std::string text =
      "# comment\n" + Imu("1.0") + "\nODOM 1.0 3 4\r\nGNSS 1.0 31.5 120.4 10.5 170.9 1 1 2 3\n";
  const ReadResult plain = ReadAll(Write("plain.gz", text));  // plain text despite the name
  const std::string gz_path = dir_ + "/compressed.txt";       // gzip despite the name
  WriteGzip(gz_path, text);
  const ReadResult gz = ReadAll(gz_path);
  ASSERT_EQ(plain.records.size(), 3u);
  ASSERT_EQ(gz.records.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(gz.records[i].type_index(), plain.records[i].type_index());
    EXPECT_EQ(gz.records[i].line, plain.records[i].line);
    EXPECT_EQ(gz.records[i].t(), plain.records[i].t());
  }
  EXPECT_EQ(gz.records[2].get<GnssRecord>().sigma_enu, Vec3(1, 2, 3));
  EXPECT_EQ(gz.stats.total_skipped(), 0u);
  EXPECT_EQ(plain.stats.total_skipped(), 0u);
}

TEST_F(LogReaderTest, ConcatenatedGzipMembersAreOneStream) {
  const std::string path = dir_ + "/log.gz";
  WriteGzip(path, Imu("1.0") + "\n");
  WriteGzip(path, Imu("2.0") + "\n", "ab");
  const ReadResult r = ReadAll(path);
  ASSERT_EQ(r.records.size(), 2u);
  EXPECT_EQ(r.records[1].line, 2u);
  EXPECT_EQ(r.stats.total_skipped(), 0u);
}

TEST_F(LogReaderTest, SharedTimeStampsAcrossTypesInEitherOrder) {
  const ReadResult r = ReadAll(Write("log.txt", Imu("1.0") +
                                                    "\n"
                                                    "GNSS 1.0 31.5 120.4 10.5 170.9 1\n"
                                                    "ODOM 1.0 1 1\n"
                                                    "ODOM 1.1 1 1\n"
                                                    "GNSS 1.1 31.5 120.4 10.5 170.9 1\n" +
                                                    Imu("1.1") + "\n"));
  EXPECT_EQ(r.records.size(), 6u);
  EXPECT_EQ(r.stats.total_skipped(), 0u);
}

TEST_F(LogReaderTest, OlderRecordOfSameTypeAndTimeIsOutOfOrderNotDuplicate) {
  const ReadResult r = ReadAll(Write("log.txt", Imu("1.0") + "\nODOM 2.0 1 1\n" + Imu("1.0") + "\n"));
  EXPECT_EQ(r.records.size(), 2u);
  EXPECT_EQ(r.stats.skipped.at("out_of_order"), 1u);
  EXPECT_EQ(r.stats.skipped.count("duplicate"), 0u);
}

// input.reorder_window_s: a record up to the window older than the newest passes (the API sorts it into
// place); older is out_of_order, measured against the newest time, not the last record read.
TEST_F(LogReaderTest, ReorderWindowLetsSlightlyOlderRecordsThrough) {
  const std::string text = Imu("2.0") + "\nGNSS 1.7 31.5 120.4 10.5 170.9 1\n" + Imu("1.9") + "\n" + Imu("1.4") +
                           "\n" + Imu("2.1") + "\n";
  InputOptions none;
  none.reorder_window = 0.0;
  const ReadResult off = ReadAll(Write("log.txt", text), none);
  EXPECT_EQ(off.records.size(), 2u);
  EXPECT_EQ(off.stats.skipped.at("out_of_order"), 3u);
  InputOptions window;
  window.reorder_window = 0.5;
  const ReadResult on = ReadAll(Write("log2.txt", text), window);
  ASSERT_EQ(on.records.size(), 4u);
  EXPECT_EQ(on.records[1].t(), 1.7);
  EXPECT_EQ(on.records[2].t(), 1.9);
  EXPECT_EQ(on.stats.skipped.at("out_of_order"), 1u);
  ASSERT_EQ(on.stats.examples.size(), 1u);
  EXPECT_EQ(on.stats.examples[0].line, 4u);
  EXPECT_NE(on.stats.examples[0].detail.find("input.reorder_window_s"), std::string::npos);
}

// GNSS stamped late by its logger is written ahead of the IMU and ODOM records up to its stamp: each of
// them is compared with the last record of its own type, so the IMU record at the fix's stamp is no
// "duplicate" (one was skipped per fix, and a whole RTK drive stamped 0.1 s late was refused).
TEST_F(LogReaderTest, RecordsReadAheadOfOthersInTheWindowAreNoDuplicates) {
  const std::string text = Imu("1.0") + "\nGNSS 1.1 31.5 120.4 10.5 170.9 1\n" + Imu("1.05") + "\nODOM 1.05 1 1\n" +
                           Imu("1.1") + "\nODOM 1.1 1 1\n" + Imu("1.15") + "\n" + Imu("1.15") + "\n";
  InputOptions window;
  window.reorder_window = 0.1;
  const ReadResult r = ReadAll(Write("log.txt", text), window);
  EXPECT_EQ(r.records.size(), 7u);
  EXPECT_EQ(r.stats.skipped.at("duplicate"), 1u);  // the real one: a second IMU record at 1.15
  EXPECT_EQ(r.stats.total_skipped(), 1u);
}

// A corrupted far-future time stamp costs that one line: the records after it are read (not out_of_order).
TEST_F(LogReaderTest, FarFutureTimeStampIsOneTimeJumpNotEveryLaterLine) {
  std::string text;
  for (int i = 0; i < 50; ++i) {
    text += Imu(std::to_string(1.0 + 0.01 * i)) + "\n";
    if (i == 10) text += Imu("1170000000.1") + "\n";  // one corrupted time stamp
  }
  const ReadResult r = ReadAll(Write("log.txt", text));
  EXPECT_EQ(r.records.size(), 50u);
  EXPECT_EQ(r.stats.skipped.size(), 1u);
  EXPECT_EQ(r.stats.skipped.at("time_jump"), 1u);
  ASSERT_EQ(r.stats.examples.size(), 1u);
  EXPECT_EQ(r.stats.examples[0].line, 12u);
  EXPECT_NE(r.stats.examples[0].detail.find("input.max_time_jump_s = 60"), std::string::npos)
      << r.stats.examples[0].detail;
  // With the limit off (0), the same log loses every later line to out_of_order instead.
  InputOptions no_limit;
  no_limit.max_time_jump = 0.0;
  const ReadResult off = ReadAll(Write("log2.txt", text), no_limit);
  EXPECT_EQ(off.records.size(), 12u);
  EXPECT_EQ(off.stats.skipped.at("out_of_order"), 39u);
}

// A clock that really jumps (10 records in a row that agree with each other) is followed after them.
TEST_F(LogReaderTest, RealClockJumpIsFollowedAfterTenRecords) {
  std::string text;
  for (int i = 0; i < 20; ++i) text += Imu(std::to_string(1.0 + 0.01 * i)) + "\n";
  for (int i = 0; i < 30; ++i) text += Imu(std::to_string(500.0 + 0.01 * i)) + "\n";
  const ReadResult r = ReadAll(Write("log.txt", text));
  EXPECT_EQ(r.stats.skipped.at("time_jump"), 9u);
  ASSERT_EQ(r.records.size(), 41u);
  EXPECT_DOUBLE_EQ(r.records[20].t(), 500.09);
  EXPECT_DOUBLE_EQ(r.records.back().t(), 500.29);
  // Ten jumped records that do not agree with each other are ten time_jump lines, and the old clock goes on.
  std::string scattered;
  for (int i = 0; i < 20; ++i) scattered += Imu(std::to_string(1.0 + 0.01 * i)) + "\n";
  for (int i = 0; i < 10; ++i) scattered += Imu(std::to_string(1000.0 * (10 - i))) + "\n";
  scattered += Imu("1.5") + "\n";
  const ReadResult s = ReadAll(Write("log2.txt", scattered));
  EXPECT_EQ(s.stats.skipped.at("time_jump"), 10u);
  EXPECT_EQ(s.records.size(), 21u);
}

// One damaged line between two good ones, and the reason it must be counted under.
struct DamageCase {
  std::string line;
  std::string reason;
};

std::vector<DamageCase> DamageCases() {
  return {
      {"IMU 1.5 0 abc 0 0 0 9.8", "bad_number"},
      {"IMU 1.5 0x10 0 0 0 0 9.8", "bad_number"},
      {"IMU 1.5 1.0.0 0 0 0 0 9.8", "bad_number"},
      {"IMU 1.5 1,5 0 0 0 0 9.8", "bad_number"},
      {"IMU 1.5 0 0 0 0 0 9.8x", "bad_number"},
      {"IMU 1.5 0 0 0 0 0 9.8\0"s, "bad_number"},
      {"ODOM 1.5 +-3 4", "bad_number"},
      {"ODOM 1.5 3 4e", "bad_number"},
      {"ODOM 1.5 - 4", "bad_number"},
      {"GNSS 1.5 31.5 120.4 10.5 170.9 yes", "bad_number"},
      {"IMU 1.5 nan 0 0 0 0 9.8", "non_finite"},
      {"IMU 1.5 0 inf 0 0 0 9.8", "non_finite"},
      {"ODOM 1.5 -Infinity 0", "non_finite"},
      {"GNSS 1.5 NaN 120.4 10.5 170.9 1", "non_finite"},
      {"GNSS 1.5 31.5 120.4 10.5 nan 0", "non_finite"},
      {"IMU 1.5 0 0 0 0 0 1e999", "non_finite"},
      {"IMU 1.5 0 0 0 0 0", "missing_fields"},
      {"IMU", "missing_fields"},
      {"ODOM 1.5 3", "missing_fields"},
      {"GNSS 1.5 31.5 120.4 10.5 170.9", "missing_fields"},
      {"GNSS 1.5 31.5 120.4 10.5 170.9 1 0.1", "missing_fields"},
      {"GNSS 1.5 31.5 120.4 10.5 170.9 1 0.1 0.1", "missing_fields"},
      {"IMU 1.5 0 0 0 0 0 9.8 1", "extra_fields"},
      {"ODOM 1.5 1 2 3", "extra_fields"},
      {"GNSS 1.5 31.5 120.4 10.5 170.9 1 0.1 0.1 0.2 7", "extra_fields"},
      {"imu 1.5 0 0 0 0 0 9.8", "unknown_type"},
      {"GPS 1.5 31.5 120.4 10.5", "unknown_type"},
      {"IMU,1.5,0,0,0,0,0,9.8", "unknown_type"},
      {"1.5 0 0 0 0 0 9.8", "unknown_type"},
      {"IMU 1.5 35.1 0 0 0 0 9.8", "absurd_value"},
      {"IMU 1.5 0 0 -40 0 0 9.8", "absurd_value"},
      {"IMU 1.5 0 0 0 -200.5 0 9.8", "absurd_value"},
      {"IMU 0 0 0 0 0 0 9.8", "absurd_value"},
      {"IMU -1.5 0 0 0 0 0 9.8", "absurd_value"},
      {"IMU 1e10 0 0 0 0 0 9.8", "absurd_value"},           // not seconds (log_limits::kMaxTime)
      {"GNSS 1.7e12 31.5 120.4 10.5 170.9 1", "absurd_value"},
      {"ODOM 1.5 1e7 0", "absurd_value"},
      {"ODOM 1.5 0 -1e7", "absurd_value"},
      {"GNSS 1.5 90.5 120.4 10.5 170.9 1", "absurd_value"},
      {"GNSS 1.5 31.5 -180.5 10.5 170.9 1", "absurd_value"},
      {"GNSS 1.5 31.5 120.4 -1000 170.9 1", "absurd_value"},
      {"GNSS 1.5 31.5 120.4 1e5 170.9 1", "absurd_value"},
      {"GNSS 1.5 31.5 120.4 10.5 360.5 1", "absurd_value"},
      {"GNSS 1.5 31.5 120.4 10.5 -361 1", "absurd_value"},
      {"GNSS 1.5 31.5 120.4 10.5 170.9 2", "absurd_value"},
      {"GNSS 1.5 31.5 120.4 10.5 170.9 0.5", "absurd_value"},
      {"GNSS 1.5 31.5 120.4 10.5 170.9 1 0 0.1 0.1", "absurd_value"},
      {"GNSS 1.5 31.5 120.4 10.5 170.9 1 0.1 -0.1 0.1", "absurd_value"},
      {"GNSS 1.5 31.5 120.4 10.5 170.9 1 0.1 0.1 1e4", "absurd_value"},
      {"GVEL 1.5 1 2", "missing_fields"},
      {"GVEL 1.5 1 2 3 0.1", "missing_fields"},
      {"GVEL 1.5 1 2 3 0.1 0.1 0.1 0.1", "extra_fields"},
      {"GVEL 1.5 1 2 x", "bad_number"},
      {"GVEL 1.5 1 2 nan", "non_finite"},
      {"GVEL 1.5 1001 2 3", "absurd_value"},
      {"GVEL 1.5 1 2 3 0.1 0 0.1", "absurd_value"},
      {Imu("0.5"), "out_of_order"},
      {"ODOM 0.899 1 1", "out_of_order"},  // 0.101 s older than the newest: beyond the default window
      {"GNSS 0.5 31.5 120.4 10.5 170.9 1", "out_of_order"},
      {Imu("1.0"), "duplicate"},
      {Imu("61.5"), "time_jump"},
      {"GNSS 1e9 31.5 120.4 10.5 170.9 1", "time_jump"},
  };
}

std::string DamagedLog(const std::string& bad_line) {
  return Imu("1.0") + "\n" + bad_line + "\n" + Imu("2.0") + "\n";
}

TEST_F(LogReaderTest, EachDamageIsSkippedAndCountedUnderItsReason) {
  int i = 0;
  for (const DamageCase& c : DamageCases()) {
    SCOPED_TRACE("line '" + c.line + "', expected " + c.reason);
    const ReadResult r = ReadAll(Write("damage" + std::to_string(i++) + ".txt", DamagedLog(c.line)));
    ASSERT_EQ(r.records.size(), 2u);
    EXPECT_EQ(r.records[0].t(), 1.0);
    EXPECT_EQ(r.records[1].t(), 2.0);
    EXPECT_EQ(r.records[1].line, 3u);
    EXPECT_EQ(r.stats.lines, 3u);
    EXPECT_EQ(r.stats.total_skipped(), 1u);
    ASSERT_EQ(r.stats.skipped.count(c.reason), 1u);
    EXPECT_EQ(r.stats.skipped.at(c.reason), 1u);
    ASSERT_EQ(r.stats.examples.size(), 1u);
    EXPECT_EQ(r.stats.examples[0].line, 2u);
    EXPECT_EQ(r.stats.examples[0].reason, c.reason);
    EXPECT_FALSE(r.stats.examples[0].detail.empty());
    EXPECT_EQ(r.stats.examples[0].detail.find('\n'), std::string::npos);
    EXPECT_EQ(r.stats.examples[0].detail.find('\0'), std::string::npos);
  }
}

TEST_F(LogReaderTest, EachDamageThrowsUnderStopPolicy) {
  InputOptions options;
  options.on_error = InputErrorPolicy::kStop;
  int i = 0;
  for (const DamageCase& c : DamageCases()) {
    SCOPED_TRACE("line '" + c.line + "', expected " + c.reason);
    const std::string path = Write("stop" + std::to_string(i++) + ".txt", DamagedLog(c.line));
    LogReader reader(path, options);
    LogRecord record;
    ASSERT_TRUE(reader.Next(&record));
    try {
      reader.Next(&record);
      ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + ":2: " + c.reason + ": "), std::string::npos) << e.what();
    }
    EXPECT_FALSE(reader.Next(&record));  // the reader stays stopped
  }
}

TEST_F(LogReaderTest, DetailNamesTheFieldAndQuotesTheToken) {
  const ReadResult r = ReadAll(Write("log.txt", DamagedLog("IMU 1.5 0 abc 0 0 0 9.8")));
  ASSERT_EQ(r.stats.examples.size(), 1u);
  EXPECT_EQ(r.stats.examples[0].detail, "field 4 (gy) 'abc' is not a number");
}

TEST_F(LogReaderTest, BinaryBytesInDetailAreEscaped) {
  const ReadResult r = ReadAll(Write("log.txt", DamagedLog("IMU 1.5 0 \x01\xff\0 0 0 0 9.8"s)));
  ASSERT_EQ(r.stats.examples.size(), 1u);
  EXPECT_EQ(r.stats.examples[0].detail, "field 4 (gy) '\\x01\\xff\\x00' is not a number");
}

TEST_F(LogReaderTest, ExamplesAreCappedPerReasonButAllAreCounted) {
  std::string text = Imu("1.0") + "\n";
  for (int i = 0; i < 12; ++i) text += "IMU 1.5 x 0 0 0 0 9.8\n";
  text += "FOO 1\n" + Imu("2.0") + "\n";
  const ReadResult r = ReadAll(Write("log.txt", text));
  EXPECT_EQ(r.records.size(), 2u);
  EXPECT_EQ(r.stats.skipped.at("bad_number"), 12u);
  EXPECT_EQ(r.stats.skipped.at("unknown_type"), 1u);
  EXPECT_EQ(r.stats.total_skipped(), 13u);
  ASSERT_EQ(r.stats.examples.size(), static_cast<size_t>(ReadStats::kMaxExamplesPerReason) + 1);
  for (int i = 0; i < ReadStats::kMaxExamplesPerReason; ++i) {
    EXPECT_EQ(r.stats.examples[i].reason, "bad_number");
    EXPECT_EQ(r.stats.examples[i].line, static_cast<uint64_t>(i + 2));
  }
  EXPECT_EQ(r.stats.examples.back().reason, "unknown_type");
  EXPECT_EQ(r.stats.examples.back().line, 14u);
}

TEST_F(LogReaderTest, TooManyDamagedLinesThrows) {
  InputOptions options;
  options.max_errors = 3;
  const std::string bad = "ODOM 1.5 1\n";
  const ReadResult ok =
      ReadAll(Write("three.txt", Imu("1.0") + "\n" + bad + bad + bad + Imu("2.0") + "\n"), options);
  EXPECT_EQ(ok.records.size(), 2u);
  EXPECT_EQ(ok.stats.total_skipped(), 3u);

  const std::string path = Write("four.txt", Imu("1.0") + "\n" + bad + bad + bad + bad + Imu("2.0") + "\n");
  try {
    ReadAll(path, options);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":5: too many damaged lines (4), last: missing_fields"),
              std::string::npos)
        << e.what();
  }
}

// A log with its times in milliseconds: refused under the default policy too with the hint the last line's
// detail gives ("not seconds?"), not only with on_error: stop.
TEST_F(LogReaderTest, TimesInMillisecondsAreRefusedWithTheHint) {
  std::string text;
  for (int i = 0; i < 20; ++i) text += Imu(std::to_string(1700000000000LL + 10 * i)) + "\n";
  InputOptions options;
  options.max_errors = 10;
  const std::string path = Write("ms.txt", text);
  try {
    ReadAll(path, options);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("too many damaged lines (11), last: absurd_value: "), std::string::npos) << what;
    EXPECT_NE(what.find("(not seconds?)"), std::string::npos) << what;
  }
}

TEST_F(LogReaderTest, LineLengthLimitIsExactAndCountsWithoutLineEnd) {
  InputOptions options;
  options.max_line_length = 40;
  const std::string line40 = Imu("1.0") + std::string(40 - Imu("1.0").size(), ' ');
  ASSERT_EQ(line40.size(), 40u);
  const ReadResult r =
      ReadAll(Write("log.txt", line40 + "\r\n" + line40 + "#\n" + Imu("2.0") + "\n"), options);
  ASSERT_EQ(r.records.size(), 2u);
  EXPECT_EQ(r.records[1].line, 3u);
  EXPECT_EQ(r.stats.skipped.at("line_too_long"), 1u);
  ASSERT_EQ(r.stats.examples.size(), 1u);
  EXPECT_EQ(r.stats.examples[0].line, 2u);
  EXPECT_NE(r.stats.examples[0].detail.find("41 characters"), std::string::npos)
      << r.stats.examples[0].detail;
}

TEST_F(LogReaderTest, HugeLineIsSkippedInBoundedMemory) {
  // Far larger than the read buffer (max_line_length + 256 KiB): it can only be skipped, not held.
  const size_t huge = 32u << 20;
  std::string text = Imu("1.0") + "\n";
  text.append(huge, 'x');
  text += "\r\n" + Imu("2.0") + "\n";
  text.append(huge, '7');  // and once more as the unterminated last line
  const ReadResult r = ReadAll(Write("log.txt", text));
  ASSERT_EQ(r.records.size(), 2u);
  EXPECT_EQ(r.records[1].line, 3u);
  EXPECT_EQ(r.stats.lines, 4u);
  EXPECT_EQ(r.stats.skipped.at("line_too_long"), 2u);
  ASSERT_EQ(r.stats.examples.size(), 2u);
  EXPECT_EQ(r.stats.examples[0].line, 2u);
  EXPECT_NE(r.stats.examples[0].detail.find(std::to_string(huge) + " characters"), std::string::npos)
      << r.stats.examples[0].detail;
  EXPECT_EQ(r.stats.examples[1].line, 4u);

  InputOptions stop;
  stop.on_error = InputErrorPolicy::kStop;
  const std::string path = dir_ + "/log.txt";
  try {
    ReadAll(path, stop);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":2: line_too_long"), std::string::npos) << e.what();
  }
  std::remove(path.c_str());  // 64 MB is too much to leave behind for inspection
}

TEST_F(LogReaderTest, LastLineWithoutNewline) {
  // A good last line without newline is a record; a damaged one was most likely cut mid-write.
  const ReadResult good = ReadAll(Write("good.txt", Imu("1.0") + "\n" + Imu("2.0")));
  EXPECT_EQ(good.records.size(), 2u);
  EXPECT_EQ(good.stats.total_skipped(), 0u);

  for (const std::string& cut :
       {"IMU 2.0 0.01 -0.0"s, "IM"s, "IMU 0"s, Imu("1.0"), "GNSS 2 31 120 10 90 1 0.1 0.1 0"s}) {
    SCOPED_TRACE(cut);
    const ReadResult r = ReadAll(Write("cut.txt", Imu("1.0") + "\n" + cut));
    EXPECT_EQ(r.records.size(), 1u);
    EXPECT_EQ(r.stats.skipped.at("truncated"), 1u);
    EXPECT_EQ(r.stats.total_skipped(), 1u);
    ASSERT_EQ(r.stats.examples.size(), 1u);
    EXPECT_EQ(r.stats.examples[0].line, 2u);
  }
}

// A gzip log of n IMU lines at t = 1, 2, ...
std::string ImuLines(int n) {
  std::string text;
  for (int i = 1; i <= n; ++i) text += Imu(std::to_string(i)) + "\n";
  return text;
}

TEST_F(LogReaderTest, TruncatedGzipEndsGracefullyAndIsCounted) {
  const std::string full_path = dir_ + "/full.gz";
  WriteGzip(full_path, ImuLines(20000));
  const std::string gz = test::ReadFile(full_path);
  ASSERT_GT(gz.size(), 1000u);
  for (const size_t keep : {size_t{1}, size_t{2}, size_t{10}, size_t{30}, gz.size() / 2, gz.size() - 9,
                            gz.size() - 4, gz.size() - 1}) {
    SCOPED_TRACE("kept " + std::to_string(keep) + " of " + std::to_string(gz.size()) + " bytes");
    const std::string path = Write("cut.gz", gz.substr(0, keep));
    const ReadResult r = ReadAll(path);
    EXPECT_EQ(r.stats.skipped.at("truncated"), 1u);
    EXPECT_EQ(r.stats.total_skipped(), 1u);
    for (size_t i = 0; i < r.records.size(); ++i) ASSERT_EQ(r.records[i].t(), static_cast<double>(i + 1));
    if (keep >= gz.size() / 2) {
      EXPECT_GT(r.records.size(), 1000u);
    }

    InputOptions stop;
    stop.on_error = InputErrorPolicy::kStop;
    try {
      ReadAll(path, stop);
      ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + ":"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(": truncated: "), std::string::npos) << e.what();
    }
  }
}

TEST_F(LogReaderTest, CorruptGzipEndsGracefully) {
  const std::string full_path = dir_ + "/full.gz";
  WriteGzip(full_path, ImuLines(20000));
  std::string gz = test::ReadFile(full_path);
  for (size_t i = gz.size() / 3; i < gz.size() / 3 + 64; ++i) gz[i] = static_cast<char>(gz[i] ^ 0x5a);
  InputOptions options;
  options.max_errors = INT_MAX;
  const ReadResult r = ReadAll(Write("corrupt.gz", gz), options);
  EXPECT_EQ(r.stats.skipped.at("truncated"), 1u);
  EXPECT_GT(r.records.size(), 100u);
}

TEST_F(LogReaderTest, BinaryGarbageNeverCrashesOrHangs) {
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> byte(0, 255);
  std::string garbage(1u << 20, '\0');
  for (char& c : garbage) c = static_cast<char>(byte(rng));
  InputOptions options;
  options.max_errors = INT_MAX;
  for (const std::string& prefix : {""s, "\x1f\x8b"s, "\x1f\x8b\x08\0\0\0\0\0\0\x03"s}) {
    SCOPED_TRACE("prefix of " + std::to_string(prefix.size()) + " bytes");
    const ReadResult r = ReadAll(Write("garbage.bin", prefix + garbage), options);
    EXPECT_TRUE(r.records.empty());
    if (prefix.empty()) {
      EXPECT_GT(r.stats.lines, 1000u);
      EXPECT_LE(r.stats.total_skipped(), r.stats.lines);  // the rest were blank or comments
      EXPECT_GT(r.stats.total_skipped(), r.stats.lines / 2);
    } else {
      EXPECT_GE(r.stats.skipped.at("truncated"), 1u);  // not a valid gzip stream
    }
  }
  // With the default limit the caller gets a clear error instead of a flood of skipped lines.
  EXPECT_THROW(ReadAll(Write("garbage2.bin", garbage)), InputError);
}

TEST_F(LogReaderTest, TinyAndEmptyFiles) {
  for (const std::string& text : {""s, "\n"s, "\x1f"s, "\x1f\x8b"s, "\0"s, "#"s, "\r"s}) {
    InputOptions options;
    options.max_errors = INT_MAX;
    const ReadResult r = ReadAll(Write("tiny.txt", text), options);
    EXPECT_TRUE(r.records.empty());
  }
  const ReadResult empty = ReadAll(Write("empty.txt", ""));
  EXPECT_EQ(empty.stats.lines, 0u);
  EXPECT_EQ(empty.stats.total_skipped(), 0u);
}

TEST_F(LogReaderTest, NextAfterEndKeepsReturningFalse) {
  LogReader reader(Write("log.txt", Imu("1.0") + "\n"), InputOptions{});
  LogRecord record;
  EXPECT_TRUE(reader.Next(&record));
  EXPECT_FALSE(reader.Next(&record));
  EXPECT_FALSE(reader.Next(&record));
  EXPECT_EQ(CountOf<ImuSample>(reader.stats().records), 1u);
}

TEST_F(LogReaderTest, MissingFileOrDirectoryCannotBeOpened) {
  const std::string missing = dir_ + "/no_such_log.txt";
  try {
    LogReader reader(missing, InputOptions{});
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), missing + ": cannot open: No such file or directory");
  }
  try {
    LogReader reader(dir_, InputOptions{});
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir_ + ": cannot open: "), std::string::npos) << e.what();
  }
}

TEST(LogReaderParseLogLineTest, ClassifiesLinesWithoutTheFile) {
  LogRecord record;
  InputIssue issue;
  EXPECT_EQ(ParseLogLine("", &record, &issue), LineParse::kBlank);
  EXPECT_EQ(ParseLogLine("  # only a comment\r", &record, &issue), LineParse::kBlank);
  ASSERT_EQ(ParseLogLine("ODOM 5 1 2\r", &record, &issue), LineParse::kRecord);
  EXPECT_TRUE(record.is<WheelRecord>());
  EXPECT_EQ(record.t(), 5.0);
  ASSERT_EQ(ParseLogLine("GNSS 6 1 2 3 4 1", &record, &issue), LineParse::kRecord);
  EXPECT_EQ(record.t(), 6.0);
  ASSERT_EQ(ParseLogLine(Imu("7"), &record, &issue), LineParse::kRecord);
  EXPECT_EQ(record.t(), 7.0);
  ASSERT_EQ(ParseLogLine("GNSS 6 1 2 3 4 1 0.1 0.1", &record, &issue), LineParse::kDamaged);
  EXPECT_EQ(issue.reason, "missing_fields");
  ASSERT_EQ(ParseLogLine("ODOM 5 1 2 3 4 5 6 7 8 9 10 11 12 13", &record, &issue), LineParse::kDamaged);
  EXPECT_EQ(issue.reason, "extra_fields");
}

// Records pushed through the API get the line checks: a parsed record passes unchanged; NaN, absurd values
// and a bad heading are damage; a valid heading is normalised as in a line.
TEST(LogReaderCheckLogRecordTest, SameRulesAsALine) {
  LogRecord record;
  InputIssue issue;
  for (const std::string& line : {Imu("7"), std::string("ODOM 5 1 2"), std::string("GNSS 6 31 120 3 -10 1 0.1 0.2 0.3"),
                                 std::string("GNSS 6 31 120 3 999 0"), std::string("GVEL 8 1 2 3 0.1 0.1 0.2")}) {
    ASSERT_EQ(ParseLogLine(line, &record, &issue), LineParse::kRecord) << line;
    const LogRecord parsed = record;
    ASSERT_EQ(CheckLogRecord(&record, &issue), LineParse::kRecord) << line << ": " << issue.detail;
    ASSERT_EQ(record.type_index(), parsed.type_index());
    EXPECT_EQ(record.t(), parsed.t());
    if (const ImuSample* imu = record.get_if<ImuSample>()) {
      EXPECT_EQ(imu->gyro, parsed.get<ImuSample>().gyro);
    }
    if (const GnssRecord* fix = record.get_if<GnssRecord>()) {
      EXPECT_EQ(fix->heading_deg, parsed.get<GnssRecord>().heading_deg);
      EXPECT_EQ(fix->sigma_enu, parsed.get<GnssRecord>().sigma_enu);
    }
    if (const GnssVelocityRecord* velocity = record.get_if<GnssVelocityRecord>()) {
      EXPECT_EQ(velocity->v_enu, parsed.get<GnssVelocityRecord>().v_enu);
    }
  }
  record = {GnssRecord{6.0, 31.0, 120.0, 3.0, -10.0, true}};
  ASSERT_EQ(CheckLogRecord(&record, &issue), LineParse::kRecord);
  EXPECT_EQ(record.get<GnssRecord>().heading_deg, 350.0);
  record.get<GnssRecord>().sigma_enu = Vec3(0.1, 0.0, 0.1);
  record.get<GnssRecord>().has_sigma = true;
  ASSERT_EQ(CheckLogRecord(&record, &issue), LineParse::kDamaged);
  EXPECT_EQ(issue.reason, "absurd_value");
  EXPECT_NE(issue.detail.find("sigma_n"), std::string::npos) << issue.detail;

  record = {};
  record.get<ImuSample>().t = 1.0;
  record.get<ImuSample>().gyro.y() = std::nan("");
  ASSERT_EQ(CheckLogRecord(&record, &issue), LineParse::kDamaged);
  EXPECT_EQ(issue.reason, "non_finite");
  EXPECT_NE(issue.detail.find("gy"), std::string::npos) << issue.detail;
  record.get<ImuSample>().gyro.y() = 0.0;
  record.get<ImuSample>().acc.z() = 1e4;
  ASSERT_EQ(CheckLogRecord(&record, &issue), LineParse::kDamaged);
  EXPECT_EQ(issue.reason, "absurd_value");
  record.get<ImuSample>().acc.z() = 9.8;
  record.get<ImuSample>().t = 0.0;
  ASSERT_EQ(CheckLogRecord(&record, &issue), LineParse::kDamaged);
  EXPECT_EQ(issue.reason, "absurd_value");
}

// The IMU's range (imu.max_gyro_rad_s, imu.max_acc_m_s2) is the config's, not fixed: a narrower one makes a
// reading inside the defaults damage, a wider one lets a reading beyond them through; lines and pushed
// records alike. The detail names the key.
TEST_F(LogReaderTest, ImuRangeFromTheOptions) {
  const std::string path = Write("range.txt",
                                 "IMU 1.0 0 0 0 0 0 9.8\n"
                                 "IMU 1.1 0 0 0 150 0 9.8\n"  // beyond a ±100 m/s² sensor
                                 "IMU 1.2 0 0 20 0 0 9.8\n"   // beyond a ±10 rad/s sensor
                                 "IMU 1.3 0 0 0 250 0 9.8\n"  // beyond the default ±200 m/s²
                                 "IMU 1.4 0 40 0 0 0 9.8\n");  // beyond the default ±35 rad/s
  const ReadResult defaults = ReadAll(path);
  EXPECT_EQ(defaults.records.size(), 3u);
  EXPECT_EQ(defaults.stats.skipped.at("absurd_value"), 2u);

  InputOptions narrow;
  narrow.imu_range = {10.0, 100.0};
  const ReadResult n = ReadAll(path, narrow);
  ASSERT_EQ(n.records.size(), 1u);
  EXPECT_EQ(n.records[0].t(), 1.0);
  EXPECT_EQ(n.stats.skipped.at("absurd_value"), 4u);

  InputOptions wide;
  wide.imu_range = {50.0, 300.0};
  const ReadResult w = ReadAll(path, wide);
  ASSERT_EQ(w.records.size(), 5u);
  EXPECT_EQ(w.records[3].get<ImuSample>().acc.x(), 250.0);
  EXPECT_EQ(w.records[4].get<ImuSample>().gyro.y(), 40.0);
  EXPECT_EQ(w.stats.total_skipped(), 0u);

  LogRecord record;
  InputIssue issue;
  ASSERT_EQ(ParseLogLine("IMU 1.1 0 0 0 150 0 9.8", &record, &issue, narrow.imu_range), LineParse::kDamaged);
  EXPECT_EQ(issue.reason, "absurd_value");
  EXPECT_NE(issue.detail.find("beyond ±100 (imu.max_acc_m_s2)"), std::string::npos) << issue.detail;
  ASSERT_EQ(ParseLogLine("IMU 1.2 0 0 20 0 0 9.8", &record, &issue, narrow.imu_range), LineParse::kDamaged);
  EXPECT_NE(issue.detail.find("beyond ±10 (imu.max_gyro_rad_s)"), std::string::npos) << issue.detail;
  record = {};
  record.get<ImuSample>().t = 1.3;
  record.get<ImuSample>().acc = Vec3(250.0, 0.0, 9.8);
  EXPECT_EQ(CheckLogRecord(&record, &issue), LineParse::kDamaged);
  EXPECT_EQ(CheckLogRecord(&record, &issue, wide.imu_range), LineParse::kRecord);
  record.get<ImuSample>().acc.x() = 150.0;
  EXPECT_EQ(CheckLogRecord(&record, &issue), LineParse::kRecord);
  EXPECT_EQ(CheckLogRecord(&record, &issue, narrow.imu_range), LineParse::kDamaged);
}

TEST(LogReaderStatsTest, TotalSkippedSumsAllReasons) {
  ReadStats stats;
  EXPECT_EQ(stats.total_skipped(), 0u);
  stats.skipped["bad_number"] = 3;
  stats.skipped["duplicate"] = 4;
  EXPECT_EQ(stats.total_skipped(), 7u);
}

// A measurement module's record (core/barometer.h) is read, range-checked and counted like any other, by its
// own codec and row: its optional σ, its field counts and its absurd values by name.
TEST(LogReaderParseLogLineTest, AModulesRecordLikeAnyOther) {
  using Baro = BarometerModule::Record;
  LogRecord record;
  InputIssue issue;
  ASSERT_EQ(ParseLogLine("BARO 5 12.5", &record, &issue), LineParse::kRecord);
  ASSERT_TRUE(record.is<Baro>());
  EXPECT_EQ(record.t(), 5.0);
  EXPECT_EQ(record.get<Baro>().alt_m, 12.5);
  EXPECT_EQ(record.get<Baro>().sigma_m, 0.0);
  EXPECT_STREQ(record.info().count_key, "baro");
  ASSERT_EQ(ParseLogLine("BARO 6 12.5 0.3", &record, &issue), LineParse::kRecord);
  EXPECT_EQ(record.get<Baro>().sigma_m, 0.3);
  ASSERT_EQ(CheckLogRecord(&record, &issue), LineParse::kRecord) << issue.detail;
  EXPECT_EQ(ParseLogLine("BARO 5", &record, &issue), LineParse::kDamaged);
  EXPECT_EQ(issue.reason, "missing_fields");
  EXPECT_EQ(ParseLogLine("BARO 5 1 2 3", &record, &issue), LineParse::kDamaged);
  EXPECT_EQ(issue.reason, "extra_fields");
  EXPECT_EQ(ParseLogLine("BARO 5 2e5", &record, &issue), LineParse::kDamaged);
  EXPECT_EQ(issue.reason, "absurd_value");
  EXPECT_NE(issue.detail.find("(alt)"), std::string::npos) << issue.detail;
  EXPECT_EQ(ParseLogLine("BARO 5 12 0", &record, &issue), LineParse::kDamaged);
  EXPECT_NE(issue.detail.find("(sigma)"), std::string::npos) << issue.detail;
  EXPECT_EQ(ParseLogLine("BARO 5 nan", &record, &issue), LineParse::kDamaged);
  EXPECT_EQ(issue.reason, "non_finite");
}

}  // namespace
}  // namespace gins
