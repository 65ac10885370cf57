// NMEA 0183 (core/io/nmea_reader.cc, nmea_parse.cc): epochs, dates and leap seconds, the σ policy, velocity
// and heading, and every kind of damage named by line under both policies.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "core/io/gnss_formats.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kWalkGps = 1440437439.75;  // 2025-08-28 17:30:21.75 UTC = 17:30:39.75 GPST
constexpr double kKnot = 1852.0 / 3600.0;

// "$<body>*HH\r\n" with its checksum (computed here, apart from the code under test).
std::string S(const std::string& body) {
  unsigned x = 0;
  for (const char c : body) x ^= static_cast<unsigned char>(c);
  char hex[8];
  std::snprintf(hex, sizeof(hex), "*%02X\r\n", x);
  return "$" + body + hex;
}

// The sentences rnx2rtkp -n writes (RMC then GGA), at a UTC time of day.
std::string Rmc(const std::string& hhmmss, const std::string& date = "280825", const std::string& speed = "0.04",
                const std::string& course = "0.00") {
  return S("GNRMC," + hhmmss + ",A,4005.8029656,N,10508.8279915,W," + speed + "," + course + "," + date + ",0.0,E,A,V");
}
std::string Gga(const std::string& hhmmss, const std::string& quality = "1", const std::string& hdop = "1.0",
                const std::string& talker = "GN") {
  return S(talker + "GGA," + hhmmss + ",4005.8029656,N,10508.8279915,W," + quality + ",15," + hdop +
           ",1600.656,M,-16.288,M,0.0,0000");
}

const double kLat = 40.0 + 5.8029656 / 60.0;
const double kLon = -(105.0 + 8.8279915 / 60.0);

struct Read {
  std::vector<LogRecord> records;
  ConvertedFile file;
  GnssFileStats stats;
};

class Nmea : public ::testing::Test {
 protected:
  void SetUp() override { path_ = test::MakeTempDir("nmea") + "/gnss.nmea"; }
  Read ReadText(const std::string& text, const InputOptions& options = {}, const GnssFormatOptions& format = {}) {
    test::WriteFile(path_, text);
    const std::unique_ptr<RecordSource> source = OpenNmea(path_, options, format);
    Read r;
    LogRecord record;
    while (source->Next(&record)) r.records.push_back(record);
    r.file = source->file();
    r.stats = source->stats();
    return r;
  }
  std::string ErrorOf(const std::string& text) {
    InputOptions stop;
    stop.on_error = InputErrorPolicy::kStop;
    try {
      ReadText(text, stop);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
  // The fixes' times.
  std::vector<double> Times(const Read& r) {
    std::vector<double> t;
    for (const LogRecord& x : r.records) {
      if (x.is<GnssRecord>()) t.push_back(x.t());
    }
    return t;
  }
  std::string path_;
};

TEST_F(Nmea, GgaWithRmcsDateIsAFixOnGpsTimeWithItsEllipsoidalHeight) {
  const Read r = ReadText(Rmc("173021.75") + Gga("173021.75"));
  ASSERT_EQ(r.records.size(), 2u);
  const GnssRecord& g = r.records[0].get<GnssRecord>();
  EXPECT_TRUE(r.records[0].is<GnssRecord>());
  EXPECT_EQ(r.records[0].line, 2u);
  EXPECT_EQ(g.t, kWalkGps);
  EXPECT_EQ(g.lat_deg, kLat);
  EXPECT_EQ(g.lon_deg, kLon);
  EXPECT_EQ(g.alt_m, 1600.656 + -16.288);  // altitude above the geoid + the geoid's height
  EXPECT_FALSE(g.heading_valid);
  EXPECT_EQ(g.sigma_enu, Vec3(2.0, 2.0, 4.0));  // no GST: HDOP 1.0 × single's 2 m, up 4 m
  EXPECT_EQ(r.stats.leap_seconds.at(18), 2u);
  const GnssVelocityRecord& v = r.records[1].get<GnssVelocityRecord>();
  EXPECT_TRUE(r.records[1].is<GnssVelocityRecord>());
  EXPECT_EQ(v.t, kWalkGps);
  EXPECT_EQ(v.v_enu, Vec3(0.0, 0.04 * kKnot, 0.0));
  EXPECT_EQ(v.sigma_enu, Vec3(0.1, 0.1, 0.5));
  EXPECT_EQ(r.file.total_skipped(), 0u);
}

TEST_F(Nmea, GstGivesTheSigmaAndHdtTheHeading) {
  const Read r = ReadText(Gga("173021.75", "4", "0.7") + S("GNGST,173021.75,0.5,0.02,0.01,30.0,0.012,0.010,0.025") +
                          S("GNHDT,123.4,T") + Rmc("173021.75"));
  ASSERT_EQ(r.records.size(), 2u);
  const GnssRecord& g = r.records[0].get<GnssRecord>();
  EXPECT_EQ(g.sigma_enu, Vec3(0.010, 0.012, 0.025));  // GST: σ lon (east), σ lat (north), σ alt
  EXPECT_TRUE(g.heading_valid);
  EXPECT_EQ(g.heading_deg, 123.4);
  EXPECT_EQ(r.stats.qualities.at("fix"), 1u);
}

TEST_F(Nmea, WithoutGstTheSigmaIsHdopTimesTheQualitysPolicy) {
  const Read r =
      ReadText(Rmc("173021.75") + Gga("173021.75", "4", "0.8") + Rmc("173022.75") + Gga("173022.75", "5", "0.8") +
               Rmc("173023.75") + Gga("173023.75", "2", "1.5") + Rmc("173024.75") + Gga("173024.75", "9", "2.0"));
  const std::vector<Vec3> want = {Vec3(0.008, 0.008, 0.016), Vec3(0.2, 0.2, 0.4), Vec3(0.75, 0.75, 1.5),
                                  Vec3(2.0, 2.0, 4.0)};
  std::vector<Vec3> got;
  for (const LogRecord& x : r.records) {
    if (x.is<GnssRecord>()) got.push_back(x.get<GnssRecord>().sigma_enu);
  }
  ASSERT_EQ(got.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_TRUE(got[i].isApprox(want[i], 1e-12)) << i << ": " << got[i].transpose();
  EXPECT_EQ(r.stats.qualities.at("fix"), 1u);
  EXPECT_EQ(r.stats.qualities.at("float"), 1u);
  EXPECT_EQ(r.stats.qualities.at("dgps"), 1u);
  EXPECT_EQ(r.stats.qualities.at("sbas"), 1u);
}

TEST_F(Nmea, VtgSpeedAndCourseBecomeAGvelWithVerticalSigmaForAGrade) {
  const Read r =
      ReadText(Rmc("173021.75", "280825", "", "") + Gga("173021.75") + S("GNVTG,90.0,T,,M,19.438,N,36.000,K,A"));
  ASSERT_EQ(r.records.size(), 2u);
  const GnssVelocityRecord& v = r.records[1].get<GnssVelocityRecord>();
  EXPECT_NEAR(v.v_enu.x(), 10.0, 1e-12);  // 36 km/h east
  EXPECT_NEAR(v.v_enu.y(), 0.0, 1e-12);
  EXPECT_EQ(v.v_enu.z(), 0.0);
  EXPECT_NEAR(v.sigma_enu.z(), 1.0, 1e-12);  // 10 % of the speed, above the 0.5 m/s floor
}

TEST_F(Nmea, ABadChecksumIsDamageNamedByLine) {
  std::string bad = Gga("173022.75");
  bad[bad.size() - 3] = bad[bad.size() - 3] == '0' ? '1' : '0';
  const std::string text = Rmc("173021.75") + Gga("173021.75") + Rmc("173022.75") + bad;
  const Read r = ReadText(text);
  EXPECT_EQ(Times(r), std::vector<double>{kWalkGps});
  EXPECT_EQ(r.file.skipped.at("bad_checksum"), 1u);
  ASSERT_EQ(r.file.issues.size(), 1u);
  EXPECT_EQ(r.file.issues[0].line, 4u);
  EXPECT_EQ(ErrorOf(text).rfind(path_ + ":4: bad_checksum: checksum '", 0), 0u) << ErrorOf(text);
}

TEST_F(Nmea, ATruncatedSentenceIsDamage) {
  const std::string gga = Gga("173022.75");
  const Read r =
      ReadText(Rmc("173021.75") + Gga("173021.75") + gga.substr(0, 30) + "\n" + Rmc("173023.75") + gga.substr(0, 40));
  EXPECT_EQ(r.file.skipped.at("truncated"), 2u);
  EXPECT_EQ(r.file.issues[0].line, 3u);
  EXPECT_EQ(r.file.issues[1].line, 5u);
  EXPECT_EQ(r.file.issues[1].detail,
            "last line has no newline and is damaged: truncated: no '*HH' checksum at the end: the sentence is cut");
  EXPECT_EQ(ErrorOf(Rmc("173021.75") + gga.substr(0, 30) + "\n"),
            path_ + ":2: truncated: no '*HH' checksum at the end: the sentence is cut");
}

TEST_F(Nmea, AnEpochBeforeAnyDateIsMissingDateUnlessDateGivesIt) {
  const std::string text = Gga("173020.75") + Rmc("173021.75") + Gga("173021.75");
  const Read r = ReadText(text);
  EXPECT_EQ(Times(r), std::vector<double>{kWalkGps});
  EXPECT_EQ(r.file.skipped.at("missing_date"), 1u);
  EXPECT_EQ(r.file.issues[0].line, 1u);
  EXPECT_EQ(ErrorOf(text), path_ +
                               ":1: missing_date: epoch of lines 1-1: no date yet (no RMC or ZDA in or before "
                               "it; --date gives the first)");
  GnssFormatOptions dated;
  ASSERT_TRUE(CalendarDays(2025, 8, 28, &dated.start_date_days));
  const Read d = ReadText(Gga("173020.75") + Gga("173021.75"), {}, dated);
  EXPECT_EQ(Times(d), (std::vector<double>{kWalkGps - 1.0, kWalkGps}));
}

TEST_F(Nmea, ZdaDatesAnEpochToo) {
  const Read r = ReadText(S("GPZDA,173021.75,28,08,2025,00,00") + Gga("173021.75"));
  EXPECT_EQ(Times(r), std::vector<double>{kWalkGps});
}

TEST_F(Nmea, TimesThatGoBackwardsAreDamage) {
  const std::string text =
      Rmc("173022.75") + Gga("173022.75") + Rmc("173021.75") + Gga("173021.75") + Rmc("173023.75") + Gga("173023.75");
  const Read r = ReadText(text);
  EXPECT_EQ(Times(r), (std::vector<double>{kWalkGps + 1.0, kWalkGps + 2.0}));
  EXPECT_EQ(r.file.skipped.at("time_backwards"), 1u);
  EXPECT_EQ(r.file.issues[0].line, 3u);
  EXPECT_EQ(ErrorOf(text), path_ +
                               ":3: time_backwards: epoch of lines 3-4: t = 1440437439.750 s is not after the "
                               "previous epoch's 1440437440.750 s");
}

TEST_F(Nmea, UndatedEpochsRollOverMidnight) {
  // RMC only once, at 23:59:59 on 28 August; the GGAs after midnight are on the 29th.
  const Read r = ReadText(Rmc("235959.00") + Gga("235959.00") + Gga("000000.00") + Gga("000001.00"));
  const std::vector<double> t = Times(r);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[1] - t[0], 1.0);
  EXPECT_EQ(t[2] - t[1], 1.0);
  EXPECT_EQ(t[1], kWalkGps - 0.75 + (6 * 3600 + 29 * 60 + 39));  // 2025-08-29 00:00:00 UTC
}

TEST_F(Nmea, ALeapSecondEpochLiesBetweenItsNeighbours) {
  const Read r = ReadText(Rmc("235959.00", "311216") + Gga("235959.00") + Rmc("235960.00", "311216") +
                          Gga("235960.00") + Rmc("000000.00", "010117") + Gga("000000.00"));
  EXPECT_EQ(Times(r), (std::vector<double>{1167264016.0, 1167264017.0, 1167264018.0}));
  EXPECT_EQ(r.stats.leap_seconds.at(17), 4u);  // two fixes and two GVELs
  EXPECT_EQ(r.stats.leap_seconds.at(18), 2u);
}

TEST_F(Nmea, AnUnknownQualityIsDamageAndNoFixOrDeadReckoningAreDropped) {
  const Read r =
      ReadText(Rmc("173021.75") + S("GNGGA,173021.75,,,,,0,00,99.99,,,,,,") + Rmc("173022.75") + Gga("173022.75", "6") +
               Rmc("173023.75") + Gga("173023.75", "X") + Rmc("173024.75") + Gga("173024.75"));
  EXPECT_EQ(Times(r), std::vector<double>{kWalkGps + 3.0});
  EXPECT_EQ(r.file.skipped.at("unknown_quality"), 1u);
  EXPECT_EQ(r.file.issues[0].line, 6u);
  EXPECT_EQ(
      ErrorOf(Rmc("173023.75") + Gga("173023.75", "X")),
      path_ + ":2: unknown_quality: fix quality 'X' is not 0-9 (0 none, 1 GPS, 2 DGPS, 4 RTK fixed, 5 float, ...)");
  EXPECT_EQ(r.stats.dropped.at("no fix (GGA quality 0)"), 1u);
  EXPECT_EQ(r.stats.dropped.at("dead reckoning (GGA quality 6)"), 1u);
}

TEST_F(Nmea, MinQualityDropsWorseFixes) {
  GnssFormatOptions fixed;
  fixed.min_quality = FixQuality::kFix;
  const Read r =
      ReadText(Rmc("173021.75") + Gga("173021.75", "5") + Rmc("173022.75") + Gga("173022.75", "4"), {}, fixed);
  EXPECT_EQ(Times(r), std::vector<double>{kWalkGps + 1.0});
  EXPECT_EQ(r.stats.dropped.at("GGA float (below --min-quality fix)"), 1u);
}

TEST_F(Nmea, AnyTalkerIsReadAndOtherSentencesAreCountedAsIgnored) {
  const Read r = ReadText(Rmc("173021.75") + Gga("173021.75", "1", "1.0", "GP") + S("GPGSV,1,1,01,10,45,120,40") +
                          Rmc("173022.75") + Gga("173022.75", "1", "1.0", "GL") + Rmc("173023.75") +
                          Gga("173023.75", "1", "1.0", "GA") + Rmc("173024.75") + Gga("173024.75", "1", "1.0", "GB") +
                          S("PUBX,00,173024.75"));
  EXPECT_EQ(Times(r).size(), 4u);
  EXPECT_EQ(r.stats.ignored.at("sentence GSV"), 1u);
  EXPECT_EQ(r.stats.ignored.at("sentence PUBX"), 1u);
  EXPECT_EQ(r.file.total_skipped(), 0u);
}

TEST_F(Nmea, TextBeforeTheSentenceIsAWarningAndOtherLinesAreNotNmea) {
  const Read r = ReadText("12:00:01.123 " + Rmc("173021.75") + Gga("173021.75") + "garbage line\n");
  EXPECT_EQ(Times(r), std::vector<double>{kWalkGps});
  EXPECT_EQ(r.file.warnings.at("text_before_sentence"), 1u);
  EXPECT_EQ(r.file.skipped.at("not_nmea"), 1u);
  EXPECT_EQ(r.file.issues.back().line, 3u);
}

}  // namespace
}  // namespace gins
