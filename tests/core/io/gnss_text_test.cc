// The pieces the GNSS-format readers share (core/io/gnss_text.h): the time forms, the leap seconds between
// UTC and the log's GPS clock (the 23:59:60 of a leap second included), and field splitting.
#include "core/io/gnss_text.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace gins {
namespace GINS_TEST_FILE {

// 2025-08-28 17:30:39.75 GPST, the rtkx walk's first epoch, in GPS seconds since 1980-01-06.
constexpr double kWalkGps = 1440437439.75;

double Calendar(const char* date, const char* time, TimeSystem system, LogTimeScale scale, int* leap = nullptr) {
  SplitTime t;
  std::string why;
  EXPECT_TRUE(ParseCalendarTime(date, time, &t, &why)) << why;
  int ignored = 0;
  return ToLogTime(t, system, scale, leap != nullptr ? leap : &ignored);
}

TEST(GnssTime, CalendarAndWeekSecondsFormsGiveTheSameGpsSeconds) {
  EXPECT_EQ(Calendar("2025/08/28", "17:30:39.750", TimeSystem::kGpst, LogTimeScale::kGps), kWalkGps);
  SplitTime t;
  std::string why;
  ASSERT_TRUE(ParseWeekSeconds("2381", "408639.750", &t, &why)) << why;
  int leap = -1;
  EXPECT_EQ(ToLogTime(t, TimeSystem::kGpst, LogTimeScale::kGps, &leap), kWalkGps);
  EXPECT_EQ(leap, 0);
  EXPECT_EQ(Calendar("2025-08-28", "17:30:39.750", TimeSystem::kGpst, LogTimeScale::kGps), kWalkGps);
}

TEST(GnssTime, UtcTimesGetTheLeapSecondsOfTheirDate) {
  int leap = 0;
  EXPECT_EQ(Calendar("2025/08/28", "17:30:21.750", TimeSystem::kUtc, LogTimeScale::kGps, &leap), kWalkGps);
  EXPECT_EQ(leap, 18);
  EXPECT_EQ(Calendar("1999/12/31", "23:59:59", TimeSystem::kUtc, LogTimeScale::kGps, &leap), 630720012.0);
  EXPECT_EQ(leap, 13);
  // GPST on a Unix log: the leap seconds come off.
  EXPECT_EQ(Calendar("2025/08/28", "17:30:39.750", TimeSystem::kGpst, LogTimeScale::kUnixUtc, &leap),
            kWalkGps + kGpsEpochUnix - 18.0);
  EXPECT_EQ(leap, 18);
  EXPECT_EQ(Calendar("2025/08/28", "17:30:21.750", TimeSystem::kUtc, LogTimeScale::kUnixUtc, &leap),
            kWalkGps + kGpsEpochUnix - 18.0);
  EXPECT_EQ(leap, 0);
}

TEST(GnssTime, TheInsertedLeapSecondFallsBetweenItsNeighbours) {
  // 2016-12-31 23:59:60 UTC: GPS − UTC is 17 s before it and 18 s from 2017-01-01 00:00:00 on.
  int leap = 0;
  const double before = Calendar("2016/12/31", "23:59:59.5", TimeSystem::kUtc, LogTimeScale::kGps, &leap);
  EXPECT_EQ(leap, 17);
  const double during = Calendar("2016/12/31", "23:59:60.5", TimeSystem::kUtc, LogTimeScale::kGps, &leap);
  EXPECT_EQ(leap, 17);
  const double after = Calendar("2017/01/01", "00:00:00.5", TimeSystem::kUtc, LogTimeScale::kGps, &leap);
  EXPECT_EQ(leap, 18);
  EXPECT_EQ(during - before, 1.0);
  EXPECT_EQ(after - during, 1.0);
  EXPECT_EQ(after, 1167264018.5);
}

TEST(GnssTime, FractionsKeepEveryDecimalTheFileWrites) {
  SplitTime t;
  std::string why;
  ASSERT_TRUE(ParseCalendarTime("2025/08/28", "17:30:39.123456789", &t, &why));
  EXPECT_EQ(t.whole, 1440437439);
  EXPECT_EQ(t.frac, 0.123456789);
  ASSERT_TRUE(ParseCalendarTime("2025/08/28", "17:30:39", &t, &why));
  EXPECT_EQ(t.frac, 0.0);
}

TEST(GnssTime, RefusesWhatIsNotACalendarTime) {
  SplitTime t;
  std::string why;
  for (const auto& [date, time] : std::vector<std::pair<const char*, const char*>>{
           {"2025/02/29", "00:00:00"},  // no 29 February in 2025
           {"2025/13/01", "00:00:00"},
           {"1980/01/05", "00:00:00"},  // before the GPS epoch
           {"2025/08/28", "24:00:00"},
           {"2025/08/28", "17:60:00"},
           {"2025/08/28", "17:30:61"},
           {"2025/08/28", "23:58:60"},  // a leap second only at 23:59
           {"2025/08/28", "17:30:1e1"},
           {"2025/08/28", "17:30:-1"},
           {"2025/08", "17:30:00"},
           {"2025/08/28", "17:30"},
       }) {
    EXPECT_FALSE(ParseCalendarTime(date, time, &t, &why)) << date << " " << time;
    EXPECT_FALSE(why.empty());
  }
  EXPECT_FALSE(ParseWeekSeconds("2381", "604800", &t, &why));  // past the week
  EXPECT_FALSE(ParseWeekSeconds("-1", "10", &t, &why));
  EXPECT_FALSE(ParseWeekSeconds("2381.5", "10", &t, &why));
}

TEST(GnssTime, NmeaTimesOfDayAndDates) {
  int64_t sod = 0, days = 0;
  double frac = 0.0;
  bool leap = true;
  ASSERT_TRUE(ParseNmeaTimeOfDay("173021.75", &sod, &frac, &leap));
  EXPECT_EQ(sod, 17 * 3600 + 30 * 60 + 21);
  EXPECT_EQ(frac, 0.75);
  EXPECT_FALSE(leap);
  ASSERT_TRUE(ParseNmeaTimeOfDay("235960", &sod, &frac, &leap));
  EXPECT_EQ(sod, 86400);
  EXPECT_TRUE(leap);
  for (const char* bad : {"1730", "240000", "176021", "17302a", "+73021", "1730211", ""}) {
    EXPECT_FALSE(ParseNmeaTimeOfDay(bad, &sod, &frac, &leap)) << bad;
  }
  ASSERT_TRUE(ParseNmeaDate("280825", &days));
  EXPECT_EQ(days, 16671);  // 2025-08-28
  ASSERT_TRUE(ParseNmeaDate("060180", &days));
  EXPECT_EQ(days, 0);
  ASSERT_TRUE(ParseNmeaDate("311299", &days));  // 1999: two-digit years from 80 are 19xx
  EXPECT_EQ(days, 7299);
  for (const char* bad : {"290225", "320825", "281325", "010180", "2808255", "28082"}) {
    EXPECT_FALSE(ParseNmeaDate(bad, &days)) << bad;
  }
}

TEST(GnssText, SplitsExactFieldsKeepingEmptyOnesAndWhitespaceRuns) {
  std::vector<std::string_view> f;
  SplitFields("GPGGA,,1,", FieldSplit::kExact, ',', &f);
  ASSERT_EQ(f.size(), 4u);
  EXPECT_EQ(f[0], "GPGGA");
  EXPECT_EQ(f[1], "");
  EXPECT_EQ(f[3], "");
  SplitFields("  2381,408621.750,  40.0 \t -105", FieldSplit::kWhitespace, ' ', &f);
  ASSERT_EQ(f.size(), 4u);
  EXPECT_EQ(f[1], "408621.750");
  EXPECT_EQ(f[3], "-105");
}

}  // namespace
}  // namespace gins
