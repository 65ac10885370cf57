// Satellite ids and the broadcast ephemeris's times (core/gnss_ephemeris.h).
#include "core/gnss_ephemeris.h"

#include <cstdio>

namespace gins {

std::string SatelliteId::ToString() const {
  char buf[8];
  std::snprintf(buf, sizeof(buf), "%c%02d", static_cast<char>(system), prn % 100);
  return buf;
}

double KeplerEphemeris::toe_gps_s() const {
  if (sat.system == GnssSystem::kBeidou) return (week + kBdtWeekOffset) * kSecondsPerWeek + toe_s + kGpsMinusBdt;
  return week * kSecondsPerWeek + toe_s;
}

}  // namespace gins
