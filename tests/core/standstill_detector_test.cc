#include "core/standstill_detector.h"

#include <gtest/gtest.h>

#include <random>

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kG = 9.8;
constexpr double kRate = 100.0;  // Hz

// A sample at rest (gravity along +z) with white noise of the given per-axis standard deviations.
ImuSample Quiet(double t, double gyro_std, double acc_std, std::mt19937_64* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  ImuSample s;
  s.t = t;
  s.gyro = gyro_std * Vec3(n(*rng), n(*rng), n(*rng));
  s.acc = Vec3(0.0, 0.0, kG) + acc_std * Vec3(n(*rng), n(*rng), n(*rng));
  return s;
}

// Driving: turns and accelerations of several m/s² and tens of deg/s.
ImuSample Driving(double t, std::mt19937_64* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  ImuSample s;
  s.t = t;
  s.gyro = Vec3(0.05 * n(*rng), 0.05 * n(*rng), 0.4 * std::sin(0.3 * t));
  s.acc = Vec3(3.0 * std::sin(0.1 * t) + 0.5 * n(*rng), 2.0 * std::cos(0.3 * t), kG + 0.8 * n(*rng));
  return s;
}

TEST(StandstillDetector, QuietImuIsStandingOnlyWhenTheWheelsAgree) {
  StandstillOptions options;
  std::mt19937_64 rng(1);
  for (bool wheels_turn : {false, true}) {
    StandstillDetector detector(options, kG, 0.1);
    for (int i = 0; i < 300; ++i) {
      const double t = i / kRate;
      detector.AddImu(Quiet(t, 0.1 * options.max_gyro_std, 0.1 * options.max_acc_std, &rng));
      if (i % 10 == 0) {
        WheelMeasurement w;
        w.t = t;
        w.interval = 0.1;
        w.standstill = !wheels_turn;
        w.speed = wheels_turn ? 5.0 : 0.0;
        detector.AddWheel(w);
      }
    }
    EXPECT_TRUE(detector.ImuQuiet());
    EXPECT_EQ(detector.Decide(), wheels_turn ? StandstillDetector::State::kMoving
                                             : StandstillDetector::State::kStanding);
  }
}

// A car cruising at constant speed on a smooth road is as quiet as a parked one: its GNSS track says it moves.
TEST(StandstillDetector, QuietCruiseIsMovingByTheGnssTrack) {
  StandstillOptions options;
  std::mt19937_64 rng(2);
  StandstillDetector detector(options, kG, 0.1);
  for (int i = 0; i < 1000; ++i) {
    const double t = i / kRate;
    detector.AddImu(Quiet(t, 0.1 * options.max_gyro_std, 0.1 * options.max_acc_std, &rng));
    if (i % 20 == 0) {
      GnssMeasurement f;
      f.t = t;
      f.p_w = Vec3(5.0 * t, 0.0, 0.0);
      detector.AddGnss(f);
    }
  }
  EXPECT_TRUE(detector.ImuQuiet());
  EXPECT_EQ(detector.Decide(), StandstillDetector::State::kMoving);
  EXPECT_EQ(detector.witness(), StandstillDetector::Witness::kGnssPosition);
}

// The window's moments are kept as running sums. After an hour of driving, a stop whose
// gyro noise is inside the threshold is still quiet, and one outside is not: the sums' rounding moves
// neither.
TEST(StandstillDetector, ThresholdsHoldAfterAnHourOfRunningSums) {
  StandstillOptions options;
  for (double fraction : {0.6, 1.5}) {
    std::mt19937_64 rng(3);
    StandstillDetector detector(options, kG, 0.1);
    int i = 0;
    for (; i < 3600 * 100; ++i) detector.AddImu(Driving(i / kRate, &rng));
    EXPECT_FALSE(detector.ImuQuiet());
    int quiet_samples = 0;
    for (int k = 0; k < 500; ++k, ++i) {
      detector.AddImu(Quiet(i / kRate, fraction * options.max_gyro_std, 0.1 * options.max_acc_std, &rng));
      quiet_samples += detector.ImuQuiet() ? 1 : 0;
    }
    if (fraction < 1.0) {
      EXPECT_GT(quiet_samples, 300) << "a stop inside the threshold";
    } else {
      EXPECT_LT(quiet_samples, 50) << "a stop outside the threshold";
    }
  }
}

}  // namespace
}  // namespace gins
