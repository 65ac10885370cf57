// A trajectory on the Earth, as the geo formats take it (core/io/geo_formats.h: KML, GPX, GeoJSON;
// core/io/nmea_sentences.h: NMEA 0183): geodetic positions (WGS84) with what a reader of a map needs beside
// them, the GNSS outages and the rejected fixes. `gins export` builds it from a run's outputs or a truth.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/conventions.h"

namespace gins {

struct GeoSample {
  double t = 0.0;  // s, the log's clock
  double lat_deg = 0.0, lon_deg = 0.0;
  double height_m = 0.0;  // ellipsoidal (WGS84)
  // Velocity east, north, up (m/s) and the body's yaw from north (deg, clockwise): only where known.
  std::optional<Vec3> v_enu;
  std::optional<double> heading_deg;
  // 1-σ of the position east, north, up (m): only where the source has it (a states CSV, not a TUM file).
  std::optional<Vec3> sigma_enu;
};

// A time interval without GNSS fixes (summary.json's gnss_outages and gnss_gaps).
struct GeoInterval {
  double t0 = 0.0, t1 = 0.0;
  std::string kind;  // "outage" (planted) or "gap" (the log has no fixes there)
};

// A GNSS fix an estimator rejected, where the fix put the antenna.
struct GeoFix {
  double t = 0.0;
  double lat_deg = 0.0, lon_deg = 0.0, height_m = 0.0;
  std::string estimator;  // "eskf", "smoother"
};

struct GeoTrack {
  std::string name;                 // the stream ("eskf", "truth", ...): the track's name in a map
  std::vector<GeoSample> samples;   // strictly increasing t
  std::vector<GeoInterval> no_fix;  // in time order, may be empty
  std::vector<GeoFix> rejected;     // in time order, may be empty
};

}  // namespace gins
