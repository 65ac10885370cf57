// The σ inflation for time-correlated GNSS errors (core/gnss_noise.h): its limits, and that it makes the
// variance of the mean of a run of Gauss–Markov errors what independent fixes with the inflated σ predict.
#include "core/gnss_noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace gins {
namespace GINS_TEST_FILE {

TEST(CorrelatedNoiseInflation, WhiteErrorsAndLongGapsKeepTheirSigma) {
  EXPECT_DOUBLE_EQ(CorrelatedNoiseInflation(0.05, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(CorrelatedNoiseInflation(0.05, -1.0), 1.0);
  EXPECT_DOUBLE_EQ(CorrelatedNoiseInflation(std::numeric_limits<double>::infinity(), 2.0), 1.0);
  EXPECT_NEAR(CorrelatedNoiseInflation(30.0, 1.0), 1.0, 1e-6);
}

TEST(CorrelatedNoiseInflation, DenseFixesApproachTwoTauOverDt) {
  // ρ = exp(−Δt/τ) → 1 − Δt/τ: (1+ρ)/(1−ρ) → 2τ/Δt.
  EXPECT_NEAR(CorrelatedNoiseInflation(0.01, 5.0), std::sqrt(2.0 * 5.0 / 0.01), 0.01);
  EXPECT_NEAR(CorrelatedNoiseInflation(0.05, 1.0), std::sqrt((1.0 + std::exp(-0.05)) / (1.0 - std::exp(-0.05))),
              1e-12);
  // A fix stamped with its predecessor's time counts as 1 ms later: large but finite.
  EXPECT_NEAR(CorrelatedNoiseInflation(0.0, 1.0), CorrelatedNoiseInflation(1e-3, 1.0), 1e-9);
}

TEST(CorrelatedNoiseInflation, MeanOfGaussMarkovRunMatchesInflatedIndependentFixes) {
  // Simulated first-order Gauss–Markov errors, 20 Hz, τ = 1 s, σ = 1 m; runs of 60 s.
  const double dt = 0.05, tau = 1.0, sigma = 1.0;
  const int n = 1200, runs = 3000;
  const double rho = std::exp(-dt / tau);
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  double sum_sq = 0.0;
  for (int r = 0; r < runs; ++r) {
    double e = sigma * normal(rng), sum = 0.0;
    for (int k = 0; k < n; ++k) {
      if (k > 0) e = rho * e + std::sqrt(1.0 - rho * rho) * sigma * normal(rng);
      sum += e;
    }
    sum_sq += (sum / n) * (sum / n);
  }
  const double var_mean = sum_sq / runs;
  const double k = CorrelatedNoiseInflation(dt, tau);
  const double predicted = sigma * sigma * k * k / n;
  // 3000 runs: the sample variance is within ±8 % (3 σ of a χ² with 3000 dof: ±7.7 %).
  EXPECT_NEAR(var_mean / predicted, 1.0, 0.08) << "k " << k;
  // Without the inflation the mean would be taken as 40 times more certain than it is.
  EXPECT_GT(var_mean / (sigma * sigma / n), 30.0);
}

}  // namespace
}  // namespace gins
