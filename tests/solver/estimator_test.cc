// The estimators' shared bookkeeping (solver/estimator.h).
#include "solver/estimator.h"

#include <gtest/gtest.h>

namespace gins {
namespace {

TEST(MeasurementCounts, OfferedIsUsedPlusEveryRejection) {
  MeasurementCounts c;
  c.used = 7;
  c.Reject("chi2_gate", 1.0);
  c.Reject("chi2_gate", 2.0);
  c.Reject("numerical", 3.0);
  const nlohmann::json j = c.ToJson();
  EXPECT_EQ(j["used"].get<uint64_t>(), 7u);
  EXPECT_EQ(j["rejected"]["chi2_gate"].get<uint64_t>(), 2u);
  EXPECT_EQ(j["rejected"]["numerical"].get<uint64_t>(), 1u);
  EXPECT_EQ(j["offered"].get<uint64_t>(), 10u);
  EXPECT_EQ(j["rejected_times"].size(), 3u);
  EXPECT_EQ(MeasurementCounts().ToJson()["offered"].get<uint64_t>(), 0u);
}

}  // namespace
}  // namespace gins
