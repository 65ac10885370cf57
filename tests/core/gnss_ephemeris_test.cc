// Satellite ids and the broadcast ephemeris's times (core/gnss_ephemeris.h).
#include <gtest/gtest.h>

#include "core/gnss_ephemeris.h"

namespace gins {
namespace GINS_TEST_FILE {

TEST(GnssEphemeris, SatelliteIdPrintsAsRinexWritesIt) {
  EXPECT_EQ((SatelliteId{GnssSystem::kGps, 5}).ToString(), "G05");
  EXPECT_EQ((SatelliteId{GnssSystem::kBeidou, 61}).ToString(), "C61");
  EXPECT_LT((SatelliteId{GnssSystem::kBeidou, 61}), (SatelliteId{GnssSystem::kGalileo, 1}));  // 'C' < 'E'
}

TEST(GnssEphemeris, ToeIsOnGpsTimeForEverySystem) {
  KeplerEphemeris e;
  e.sat = {GnssSystem::kGalileo, 7};
  e.week = 2381;  // Galileo's RINEX week is the GPS week
  e.toe_s = 407400.0;
  EXPECT_DOUBLE_EQ(e.toe_gps_s(), 2381 * kSecondsPerWeek + 407400.0);
  // BeiDou: BDT week 1025 = GPS week 2381; BDT = GPS − 14 s.
  e.sat = {GnssSystem::kBeidou, 21};
  e.week = 1025;
  e.toe_s = 406800.0;
  EXPECT_DOUBLE_EQ(e.toe_gps_s(), 2381 * kSecondsPerWeek + 406800.0 + 14.0);
}

}  // namespace
}  // namespace gins
