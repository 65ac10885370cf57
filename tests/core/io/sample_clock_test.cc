// Time-stamp regularisation (core/io/sample_clock.h): a regular stream passes bit for bit, a rate change too;
// a logger's ±20 ms of jitter comes back to within a few milliseconds of the sensor's grid, increasing; a
// gap starts a new run.
#include "core/io/sample_clock.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace gins {
namespace GINS_TEST_FILE {

TEST(SampleClock, RegularStreamsAndRateChangesPassUnchanged) {
  SampleClock clock(0.5);
  double t = 1700000000.0;
  for (int k = 0; k < 3000; ++k) {
    t += k < 1000 ? 0.01 : (k < 2000 ? 0.005 : 0.02);  // 100, 200, 50 Hz
    EXPECT_EQ(clock.Stamp(t), t) << k;
  }
  EXPECT_EQ(clock.regularized(), 0u);
}

TEST(SampleClock, JitterComesBackToTheGrid) {
  SampleClock clock(0.5);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  const double t0 = 1700000000.0, period = 0.01;
  double sum_sq_raw = 0.0, sum_sq = 0.0, worst = 0.0, last = 0.0;
  int n = 0;
  for (int k = 0; k < 6000; ++k) {
    const double truth = t0 + k * period;
    const double raw = truth + jitter(rng);
    const double out = clock.Stamp(raw);
    if (k < 200) continue;  // the first window: raw until the jitter is judged
    EXPECT_GT(out, last) << k;
    last = out;
    sum_sq_raw += (raw - truth) * (raw - truth);
    sum_sq += (out - truth) * (out - truth);
    worst = std::max(worst, std::abs(out - truth));
    ++n;
  }
  const double rms_raw = std::sqrt(sum_sq_raw / n), rms = std::sqrt(sum_sq / n);
  std::printf("jitter ±20 ms at 100 Hz: raw %.2f ms RMS, regularised %.2f ms RMS (max %.2f ms)\n", 1e3 * rms_raw,
              1e3 * rms, 1e3 * worst);
  EXPECT_GT(rms_raw, 0.011);
  EXPECT_LT(rms, 0.004);
  EXPECT_LT(worst, 0.012);
  EXPECT_GT(clock.regularized(), 5000u);
  EXPECT_LT(clock.max_correction(), 0.03);
}

TEST(SampleClock, AGapStartsANewRunAndADroppedSampleCostsAtMostAPeriod) {
  SampleClock clock(0.5);
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  const double t0 = 1700000000.0, period = 0.01;
  double worst_after_drop = 0.0;
  for (int k = 0; k < 4000; ++k) {
    if (k == 2000) continue;  // one sample lost
    const double truth = t0 + k * period + (k >= 3000 ? 1.0 : 0.0);  // a 1 s gap at 3000
    const double raw = truth + jitter(rng);
    const double out = clock.Stamp(raw);
    if (k == 3000) {
      EXPECT_EQ(out, raw) << "a gap: the raw stamp";
    }
    if (k > 2000 && k < 3000) worst_after_drop = std::max(worst_after_drop, std::abs(out - truth));
  }
  EXPECT_LT(worst_after_drop, period + 0.01);
}

}  // namespace
}  // namespace gins
