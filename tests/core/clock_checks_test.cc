#include "core/clock_checks.h"

#include <gtest/gtest.h>

#include <cmath>

namespace gins {
namespace GINS_TEST_FILE {

// A car driving a straight road for 300 s with its speed changing (about 1 m/s² peaks: stops and starts),
// IMU at 100 Hz (forward specific force = the speed's rate, plus a pitch's constant), 1 Hz RTK fixes stamped
// `gnss_late` s after the IMU time of their position.
ClockOffsetCheck::Outcome Drive(double gnss_late, ClockOffsetCheck* check) {
  const auto accel = [](double t) { return 1.0 * std::sin(2 * M_PI * t / 37.0) + 0.6 * std::sin(2 * M_PI * t / 11.0); };
  double v = 10.0, x = 0.0;
  std::vector<std::pair<double, double>> track;  // (t, x)
  for (int k = 0; k <= 30000; ++k) {
    const double t = 1000.0 + 0.01 * k;
    check->AddImu(t, Vec3(accel(t) + 0.05, 0.0, 9.8));
    if (k % 100 == 0) track.emplace_back(t, x);
    v += accel(t) * 0.01;
    x += v * 0.01;
    // The fixes come in stamp order among the IMU's (a fix stamped late arrives later).
    while (!track.empty() && track.front().first + gnss_late <= t) {
      check->AddFix(track.front().first + gnss_late, Vec3(track.front().second, 0.0, 0.0), 0.02);
      track.erase(track.begin());
    }
  }
  return check->outcome();
}

TEST(ClockOffsetCheck, StreamsOnTheSameClockAreOk) {
  for (const double late : {0.0, 0.1, 0.25}) {  // latency below a second is the offset state's
    ClockOffsetCheck check;
    EXPECT_EQ(Drive(late, &check), ClockOffsetCheck::Outcome::kOk) << late;
    EXPECT_GT(check.Correlation(0), 0.8) << late;
  }
}

TEST(ClockOffsetCheck, LeapSecondsAreRefusedAndNamed) {
  ClockOffsetCheck check;
  EXPECT_EQ(Drive(18.0, &check), ClockOffsetCheck::Outcome::kRefuse);
  EXPECT_NE(check.message().find("stamped 18 s after the IMU's"), std::string::npos) << check.message();
  EXPECT_NE(check.message().find("leap seconds"), std::string::npos) << check.message();
  EXPECT_NE(check.message().find("gnss.time_offset_s: 18"), std::string::npos) << check.message();
  ClockOffsetCheck early;
  EXPECT_EQ(Drive(-3.0, &early), ClockOffsetCheck::Outcome::kRefuse);
  EXPECT_NE(early.message().find("gnss.time_offset_s: -3"), std::string::npos) << early.message();
}

TEST(ClockOffsetCheck, ACruiseAtConstantSpeedSaysNothing) {
  ClockOffsetCheck check;
  for (int k = 0; k <= 30000; ++k) {
    const double t = 0.01 * k;
    check.AddImu(t, Vec3(0.0, 0.0, 9.8));
    if (k % 100 == 0) check.AddFix(t + 18.0, Vec3(10.0 * t, 0.0, 0.0), 0.02);
  }
  EXPECT_EQ(check.outcome(), ClockOffsetCheck::Outcome::kPending);
}

}  // namespace
}  // namespace gins
