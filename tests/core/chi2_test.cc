#include "core/chi2.h"

#include <gtest/gtest.h>

namespace gins {
namespace GINS_TEST_FILE {

TEST(Chi2, QuantilesMatchTables) {
  EXPECT_NEAR(Chi2Quantile(0.95, 1), 3.841459, 1e-5);
  EXPECT_NEAR(Chi2Quantile(0.99, 3), 11.344867, 1e-5);
  EXPECT_NEAR(Chi2Quantile(0.999, 2), 13.815511, 1e-5);
  EXPECT_NEAR(Chi2Quantile(0.9999, 3), 21.107513, 1e-5);
  EXPECT_NEAR(Chi2Quantile(0.5, 9), 8.342833, 1e-5);
  EXPECT_NEAR(Chi2Cdf(Chi2Quantile(0.3, 4), 4), 0.3, 1e-10);
}

}  // namespace
}  // namespace gins
