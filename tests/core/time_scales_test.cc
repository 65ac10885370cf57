#include "core/time_scales.h"

#include <gtest/gtest.h>

#include <cmath>

namespace gins {
namespace GINS_TEST_FILE {

// Unix UTC of 2017-01-01 00:00:00: the 18th leap second was inserted just before it.
constexpr double kLeap2017 = 1483228800.0;

TEST(TimeScales, GpsToUtcAtAKnownInstant) {
  // GPS second 1440437440 = 2025-08-28 17:30:22 UTC (18 leap seconds).
  EXPECT_EQ(GpsToUnixUtc(1440437440.0), 1756402222.0);
  EXPECT_EQ(UnixUtcToGps(1756402222.0), 1440437440.0);
  EXPECT_EQ(GpsMinusUtc(1756402222.0), 18);
  const UtcCalendar c = ToUtcCalendar(GpsToUnixUtc(1440437440.0));
  EXPECT_EQ(c.year, 2025);
  EXPECT_EQ(c.month, 8);
  EXPECT_EQ(c.day, 28);
  EXPECT_EQ(c.hour, 17);
  EXPECT_EQ(c.minute, 30);
  EXPECT_EQ(c.second, 22.0);
  EXPECT_EQ(IsoUtc(GpsToUnixUtc(1440437440.0), 0), "2025-08-28T17:30:22Z");
}

// Any double gives a calendar (the bound's), none an out-of-range cast; HasDate says which times have one.
TEST(TimeScales, HugeTimesGiveTheBoundsCalendarAndNoDate) {
  const UtcCalendar far = ToUtcCalendar(1.96769e+128);
  EXPECT_EQ(far.year, ToUtcCalendar(1e15).year);
  EXPECT_GT(far.year, 30000000);
  EXPECT_EQ(ToUtcCalendar(std::nan("")).year, 1970);
  EXPECT_TRUE(HasDate(1440437440.0));
  EXPECT_FALSE(HasDate(5e7));
  EXPECT_FALSE(HasDate(1e10));
}

TEST(TimeScales, TheGpsEpochHasNoLeapSeconds) {
  EXPECT_EQ(GpsToUnixUtc(0.0), kGpsEpochUnix);
  EXPECT_EQ(UnixUtcToGps(kGpsEpochUnix), 0.0);
  EXPECT_EQ(GpsMinusUtc(kGpsEpochUnix), 0);
  EXPECT_EQ(IsoUtc(kGpsEpochUnix, 3), "1980-01-06T00:00:00.000Z");
  // The first leap second: 1981-07-01.
  EXPECT_EQ(GpsMinusUtc(362793600.0 - 0.5), 0);
  EXPECT_EQ(GpsMinusUtc(362793600.0), 1);
}

TEST(TimeScales, TheLeapSecondOf2016RepeatsTheLastSecondOfTheYear) {
  EXPECT_EQ(GpsMinusUtc(kLeap2017 - 0.001), 17);
  EXPECT_EQ(GpsMinusUtc(kLeap2017), 18);
  // 2016-12-31 23:59:59 UTC is GPS 1167264016; the inserted 23:59:60 is GPS 1167264017; 2017-01-01 00:00:00 is
  // GPS 1167264018.
  EXPECT_EQ(UnixUtcToGps(kLeap2017 - 1.0), 1167264016.0);
  EXPECT_EQ(UnixUtcToGps(kLeap2017), 1167264018.0);
  EXPECT_EQ(GpsToUnixUtc(1167264016.0), kLeap2017 - 1.0);
  EXPECT_EQ(GpsToUnixUtc(1167264016.5), kLeap2017 - 0.5);
  EXPECT_EQ(GpsToUnixUtc(1167264017.0), kLeap2017 - 1.0);  // the leap second reads 23:59:59 again
  EXPECT_EQ(GpsToUnixUtc(1167264017.5), kLeap2017 - 0.5);
  EXPECT_EQ(GpsToUnixUtc(1167264018.0), kLeap2017);
  EXPECT_EQ(IsoUtc(GpsToUnixUtc(1167264017.25), 2), "2016-12-31T23:59:59.25Z");
  EXPECT_EQ(IsoUtc(GpsToUnixUtc(1167264018.0), 2), "2017-01-01T00:00:00.00Z");
}

TEST(TimeScales, GpsUtcRoundTripAwayFromLeapSeconds) {
  // Quarter seconds are exact in a double at these magnitudes, so the round trip is exact.
  int checked = 0;
  for (double t = 0.25; t < 1.6e9; t += 86400.0 * 7.0 + 3600.25) {
    const double unix_utc = GpsToUnixUtc(t);
    ASSERT_EQ(UnixUtcToGps(unix_utc), t) << t;
    ASSERT_EQ(GpsToUnixUtc(UnixUtcToGps(unix_utc)), unix_utc) << t;
    ++checked;
  }
  EXPECT_GT(checked, 2000);
  // Either side of every leap second.
  for (const double unix_day : {362793600.0, 567993600.0, 915148800.0, 1136073600.0, 1435708800.0, kLeap2017}) {
    for (const double offset : {-1.5, -0.75, 0.0, 0.25, 1.0}) {
      const double unix_utc = unix_day + offset;
      EXPECT_EQ(GpsToUnixUtc(UnixUtcToGps(unix_utc)), unix_utc) << unix_utc;
    }
  }
}

TEST(TimeScales, LogTimeScales) {
  EXPECT_EQ(LogTimeToUnixUtc(1440437440.0, LogTimeScale::kGps), 1756402222.0);
  EXPECT_EQ(LogTimeToUnixUtc(1756402222.5, LogTimeScale::kUnixUtc), 1756402222.5);
  EXPECT_EQ(UnixUtcToLogTime(1756402222.0, LogTimeScale::kGps), 1440437440.0);
  EXPECT_EQ(UnixUtcToLogTime(1756402222.5, LogTimeScale::kUnixUtc), 1756402222.5);
}

TEST(TimeScales, ParseLogTimeScale) {
  LogTimeScale scale = LogTimeScale::kUnixUtc;
  ASSERT_TRUE(ParseLogTimeScale("gps", &scale));
  EXPECT_EQ(scale, LogTimeScale::kGps);
  ASSERT_TRUE(ParseLogTimeScale("unix", &scale));
  EXPECT_EQ(scale, LogTimeScale::kUnixUtc);
  for (const char* bad : {"GPS", "utc", "", "gps ", "tai"}) {
    scale = LogTimeScale::kGps;
    EXPECT_FALSE(ParseLogTimeScale(bad, &scale)) << bad;
    EXPECT_EQ(scale, LogTimeScale::kGps) << bad;  // left alone
  }
  EXPECT_STREQ(LogTimeScaleName(LogTimeScale::kGps), "gps");
  EXPECT_STREQ(LogTimeScaleName(LogTimeScale::kUnixUtc), "unix");
  for (const LogTimeScale s : {LogTimeScale::kGps, LogTimeScale::kUnixUtc}) {
    ASSERT_TRUE(ParseLogTimeScale(LogTimeScaleName(s), &scale));
    EXPECT_EQ(scale, s);
  }
}

void ExpectCalendar(const UtcCalendar& c, int year, int month, int day, int hour, int minute, double second) {
  EXPECT_EQ(c.year, year);
  EXPECT_EQ(c.month, month);
  EXPECT_EQ(c.day, day);
  EXPECT_EQ(c.hour, hour);
  EXPECT_EQ(c.minute, minute);
  EXPECT_EQ(c.second, second);
}

TEST(TimeScales, CalendarRoundTripOnLeapYears) {
  // 2000 is a leap year (divisible by 400), 2100 is not (by 100).
  EXPECT_EQ(FromUtcCalendar({2000, 2, 29, 0, 0, 0.0}), 951782400.0);
  EXPECT_EQ(FromUtcCalendar({2100, 3, 1, 0, 0, 0.0}), 4107542400.0);
  EXPECT_EQ(FromUtcCalendar({2100, 2, 28, 0, 0, 0.0}) + 86400.0, 4107542400.0);
  ExpectCalendar(ToUtcCalendar(951782400.0 + 45296.5), 2000, 2, 29, 12, 34, 56.5);
  ExpectCalendar(ToUtcCalendar(951782400.0 + 86400.0), 2000, 3, 1, 0, 0, 0.0);
  ExpectCalendar(ToUtcCalendar(4107542400.0 - 0.25), 2100, 2, 28, 23, 59, 59.75);
  ExpectCalendar(ToUtcCalendar(0.0), 1970, 1, 1, 0, 0, 0.0);
  ExpectCalendar(ToUtcCalendar(-0.5), 1969, 12, 31, 23, 59, 59.5);
  for (const UtcCalendar& c : {UtcCalendar{2000, 2, 29, 12, 34, 56.5}, UtcCalendar{2100, 3, 1, 23, 59, 59.75},
                               UtcCalendar{2024, 12, 31, 0, 0, 0.0}, UtcCalendar{1980, 1, 6, 0, 0, 0.0}}) {
    const UtcCalendar back = ToUtcCalendar(FromUtcCalendar(c));
    ExpectCalendar(back, c.year, c.month, c.day, c.hour, c.minute, c.second);
  }
  // Every day from 1970 to 2200 follows the one before it.
  UtcCalendar prev = ToUtcCalendar(0.0);
  for (double t = 86400.0; t < FromUtcCalendar({2200, 1, 1, 0, 0, 0.0}); t += 86400.0) {
    const UtcCalendar c = ToUtcCalendar(t);
    const bool next_day = c.year == prev.year && c.month == prev.month && c.day == prev.day + 1;
    const bool next_month = c.year == prev.year && c.month == prev.month + 1 && c.day == 1;
    const bool next_year = c.year == prev.year + 1 && c.month == 1 && prev.month == 12 && c.day == 1;
    ASSERT_TRUE(next_day || next_month || next_year) << c.year << "-" << c.month << "-" << c.day;
    ASSERT_EQ(FromUtcCalendar(c), t);
    prev = c;
  }
}

TEST(TimeScales, IsoUtcRoundsOnceIntoTheNextMinute) {
  const double t = FromUtcCalendar({2024, 6, 1, 12, 34, 59.9996});
  EXPECT_EQ(IsoUtc(t, 3), "2024-06-01T12:35:00.000Z");
  EXPECT_EQ(IsoUtc(t, 4), "2024-06-01T12:34:59.9996Z");
  EXPECT_EQ(IsoUtc(t, 0), "2024-06-01T12:35:00Z");
  EXPECT_EQ(IsoUtc(FromUtcCalendar({2024, 6, 1, 12, 34, 59.4}), 0), "2024-06-01T12:34:59Z");
  EXPECT_EQ(IsoUtc(FromUtcCalendar({2024, 12, 31, 23, 59, 59.9996}), 3), "2025-01-01T00:00:00.000Z");
  EXPECT_EQ(IsoUtc(FromUtcCalendar({2024, 6, 1, 0, 0, 0.0}), 3), "2024-06-01T00:00:00.000Z");
}

}  // namespace
}  // namespace gins
