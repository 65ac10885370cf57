// Simulated GNSS outage windows (core/gnss_outages.h): membership at the window edges, the periodic pattern,
// the absolute windows a run reports, and gaps in a log's own GNSS stream.
#include "core/eval/gnss_outages.h"

#include <gtest/gtest.h>

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kFirst = 1700000000.0;

TEST(GnssOutageSchedule, EmptyDropsNothing) {
  const GnssOutageSchedule none;
  EXPECT_TRUE(none.empty());
  EXPECT_FALSE(none.Contains(kFirst + 10.0, kFirst));
  EXPECT_TRUE(none.Windows(kFirst, kFirst + 1000.0).empty());
  // A periodic pattern of zero duration is none.
  EXPECT_TRUE(GnssOutageSchedule({}, 10.0, 0.0, 60.0).empty());
}

TEST(GnssOutageSchedule, ExplicitWindowsAreHalfOpen) {
  const GnssOutageSchedule s({{300.0, 60.0}, {100.0, 5.0}}, 0.0, 0.0, 0.0);
  EXPECT_FALSE(s.empty());
  EXPECT_FALSE(s.Contains(kFirst + 299.0, kFirst));
  EXPECT_TRUE(s.Contains(kFirst + 300.0, kFirst));  // start included
  EXPECT_TRUE(s.Contains(kFirst + 359.5, kFirst));
  EXPECT_FALSE(s.Contains(kFirst + 360.0, kFirst));  // end excluded: 60 fixes at 1 Hz
  EXPECT_TRUE(s.Contains(kFirst + 102.0, kFirst));
  int dropped = 0;
  for (int k = 0; k < 1000; ++k) dropped += s.Contains(kFirst + k, kFirst);
  EXPECT_EQ(dropped, 65);
  // Absolute, sorted; a window starting after the log's end is not reported.
  const auto w = s.Windows(kFirst, kFirst + 330.0);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_EQ(w[0], std::make_pair(kFirst + 100.0, kFirst + 105.0));
  EXPECT_EQ(w[1], std::make_pair(kFirst + 300.0, kFirst + 360.0));
  EXPECT_EQ(s.Windows(kFirst, kFirst + 299.9).size(), 1u);
  EXPECT_EQ(s.Windows(kFirst, kFirst + 300.0).size(), 2u);  // a fix at the log's last time may be dropped
}

TEST(GnssOutageSchedule, PeriodicPattern) {
  // 60 s every 180 s from 250 s: [250, 310), [430, 490), [610, 670), ...
  const GnssOutageSchedule s({}, 250.0, 60.0, 180.0);
  EXPECT_FALSE(s.Contains(kFirst + 249.9, kFirst));
  EXPECT_TRUE(s.Contains(kFirst + 250.0, kFirst));
  EXPECT_TRUE(s.Contains(kFirst + 309.9, kFirst));
  EXPECT_FALSE(s.Contains(kFirst + 310.0, kFirst));
  EXPECT_TRUE(s.Contains(kFirst + 430.0, kFirst));
  EXPECT_TRUE(s.Contains(kFirst + 669.0, kFirst));
  EXPECT_FALSE(s.Contains(kFirst + 700.0, kFirst));
  const auto w = s.Windows(kFirst, kFirst + 700.0);
  ASSERT_EQ(w.size(), 3u);
  EXPECT_EQ(w[2], std::make_pair(kFirst + 610.0, kFirst + 670.0));
  int dropped = 0;
  for (int k = 0; k <= 700; ++k) dropped += s.Contains(kFirst + k, kFirst);
  EXPECT_EQ(dropped, 180);
}

TEST(GnssOutageSchedule, OverlappingWindowsAreMergedInTheReport) {
  const GnssOutageSchedule s({{240.0, 20.0}, {500.0, 10.0}}, 250.0, 60.0, 180.0);
  const auto w = s.Windows(kFirst, kFirst + 520.0);
  ASSERT_EQ(w.size(), 3u);
  EXPECT_EQ(w[0], std::make_pair(kFirst + 240.0, kFirst + 310.0));
  EXPECT_EQ(w[1], std::make_pair(kFirst + 430.0, kFirst + 490.0));
  EXPECT_EQ(w[2], std::make_pair(kFirst + 500.0, kFirst + 510.0));
}

TEST(GnssGapTracker, RecordsGapsLongerThanTheThreshold) {
  GnssGapTracker g(3.0);
  for (double t : {0.0, 1.0, 2.0, 5.0, 9.5, 10.0, 10.0, 11.0, 40.0}) g.Add(kFirst + t);
  ASSERT_EQ(g.gaps().size(), 2u);  // 2 -> 5 is exactly 3 s: not a gap
  EXPECT_EQ(g.gaps()[0], std::make_pair(kFirst + 5.0, kFirst + 9.5));
  EXPECT_EQ(g.gaps()[1], std::make_pair(kFirst + 11.0, kFirst + 40.0));
}

}  // namespace
}  // namespace gins
