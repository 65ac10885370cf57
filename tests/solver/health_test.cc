// The health verdict (solver/health.h) from an estimator's counts: each rule at its bound.
#include "solver/health.h"

#include <gtest/gtest.h>

namespace gins {
namespace GINS_TEST_FILE {

nlohmann::json Stats(uint64_t used, uint64_t rejected, uint64_t resets) {
  nlohmann::json j;
  j["gnss_position"]["used"] = used;
  j["gnss_position"]["rejected"] = nlohmann::json::object();
  if (rejected > 0) j["gnss_position"]["rejected"]["chi2_gate"] = rejected;
  j["watchdog"]["count"] = resets;
  return j;
}

TEST(Health, OkWhenFewFixesAreRejectedAndNothingElseHappened) {
  const Health h = JudgeHealth(Stats(1000, 50, 0));  // 4.8 %
  EXPECT_EQ(h.verdict, "ok");
  EXPECT_TRUE(h.ok());
  EXPECT_TRUE(h.reasons.empty());
  EXPECT_EQ(h.Describe(), "ok");
}

TEST(Health, DegradedAboveOneFixInTwentyOrAfterAReset) {
  const Health many = JudgeHealth(Stats(1000, 53, 0));  // 5.03 %
  EXPECT_EQ(many.verdict, "degraded");
  EXPECT_EQ(many.Describe(), "degraded: 53 of 1053 GNSS fixes rejected (5.0 %)");
  EXPECT_EQ(JudgeHealth(Stats(1000, 0, 1)).verdict, "degraded");
  EXPECT_EQ(JudgeHealth(Stats(1000, 0, 2)).verdict, "degraded");
  nlohmann::json cov = Stats(1000, 0, 0);
  cov["covariance_failures"] = 2;
  EXPECT_EQ(JudgeHealth(cov).verdict, "degraded");
  nlohmann::json batch = Stats(1000, 0, 0);
  batch["batch"]["covariance_ok"] = false;
  EXPECT_EQ(JudgeHealth(batch).verdict, "degraded");
  EXPECT_EQ(JudgeHealth(Stats(1000, 0, 0), 3).verdict, "degraded");
}

TEST(Health, FailedWhenMostFixesAreRejectedOrTheWatchdogKeepsFiring) {
  const Health most = JudgeHealth(Stats(10, 11, 1));
  EXPECT_EQ(most.verdict, "failed");
  ASSERT_EQ(most.reasons.size(), 2u);  // the failure first, then what only degrades
  EXPECT_EQ(most.reasons[0], "11 of 21 GNSS fixes rejected (52.4 %)");
  EXPECT_EQ(most.reasons[1], "1 watchdog re-initialisation");
  EXPECT_EQ(JudgeHealth(Stats(1000, 0, 3)).verdict, "failed");
  // Half exactly is not most; and a handful of fixes says little either way.
  EXPECT_EQ(JudgeHealth(Stats(10, 10, 0)).verdict, "degraded");
  EXPECT_EQ(JudgeHealth(Stats(2, 7, 0)).verdict, "degraded");
}

}  // namespace
}  // namespace gins
