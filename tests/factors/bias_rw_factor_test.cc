#include "factors/bias_rw_factor.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "factor_test_util.h"
#include "factors/scale_rw_factor.h"

namespace gins {
namespace GINS_TEST_FILE {

TEST(BiasRwFactorTest, ResidualIsWhitenedDifference) {
  const double sg = 3e-4, sa = 2e-4, dt = 0.25;
  Vec6 b_i, b_j;
  b_i << 0.01, -0.02, 0.005, 0.1, 0.05, -0.08;
  b_j = b_i;
  Vec6 r;
  BiasRwFactor(sg, sa, dt)(b_i.data(), b_j.data(), r.data());
  EXPECT_LT(r.norm(), 1e-15);
  // A one-σ step of the random walk over dt on each axis is a unit residual.
  b_j.head<3>().array() += sg * std::sqrt(dt);
  b_j.tail<3>().array() -= sa * std::sqrt(dt);
  BiasRwFactor(sg, sa, dt)(b_i.data(), b_j.data(), r.data());
  Vec6 expected;
  expected << 1, 1, 1, -1, -1, -1;
  EXPECT_LT((r - expected).norm(), 1e-9);
}

TEST(BiasRwFactorTest, JacobiansMatchNumeric) {
  std::mt19937 rng(18);
  std::unique_ptr<ceres::CostFunction> cost(BiasRwFactor::Create(3e-4, 2e-4, 0.5));
  Vec6 b_i, b_j;
  b_i << test::RandomVec3(rng, 0.01), test::RandomVec3(rng, 0.1);
  b_j << test::RandomVec3(rng, 0.01), test::RandomVec3(rng, 0.1);
  const double worst =
      test::CheckJacobians(*cost, {nullptr, nullptr}, {b_i.data(), b_j.data()}, 1e-6, "bias rw");
  std::printf("[ bias jac ] worst relative error: %.2g\n", worst);
}

TEST(ScaleRwFactorTest, ResidualAndJacobians) {
  const double s_i = 1.0, s_j = 1.0 + 1e-4 * std::sqrt(4.0);
  double r = 0.0;
  ScaleRwFactor(1e-4, 4.0)(&s_i, &s_j, &r);
  EXPECT_NEAR(r, 1.0, 1e-9);
  std::unique_ptr<ceres::CostFunction> cost(ScaleRwFactor::Create(1e-4, 4.0));
  test::CheckJacobians(*cost, {nullptr, nullptr}, {&s_i, &s_j}, 1e-6, "scale rw");
}

}  // namespace
}  // namespace gins
