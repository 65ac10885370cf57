// A GeoTrack (core/io/geo_track.h) as the geo formats GIS clients open: KML 2.2 (Google Earth), GPX 1.1
// (GPS tools), GeoJSON (RFC 7946; QGIS, web maps). The three carry the same features, so a map shows the
// same thing whichever file it was given:
//   - the track split at its no-fix intervals: one line feature per piece, of kind "track" between the
//     intervals and "outage" / "gap" (the interval's kind) for the samples inside one (t0 <= t <= t1), the
//     estimate coasting without fixes. Consecutive pieces share their boundary sample, so the drawn line
//     has no hole. A piece of fewer than 2 vertices is no line; a track of 1 sample is a point of kind
//     "track". An interval with no sample inside splits nothing.
//   - one point feature of kind "rejected_fix" per rejected fix.
// Properties (KML ExtendedData, GPX <extensions>, GeoJSON properties): kind; a line's t_start and t_end, a
// point's t (the log's clock, s); a rejected fix's estimator; and where the time is absolute its ISO UTC
// (utc_start / utc_end, utc), also as the format's own time elements (KML TimeSpan / TimeStamp, GPX <time>).
// Each feature's name is "<track name> <kind>" or "rejected fix (<estimator>) t=<t>".
// Layout for a reader (`ogrinfo -al`): KML has a Folder, so a layer, "lines" and one "points" (either only
// if not empty); GPX has layers waypoints (points) and tracks (lines, one <trk> of one <trkseg> each);
// GeoJSON is one FeatureCollection, points first, each line with a "times" array (t per vertex).
// Heights are ellipsoidal (WGS84): KML altitudeMode absolute, GPX <ele>, GeoJSON the third coordinate.
#pragma once

#include <cstdio>

#include "core/io/geo_track.h"
#include "core/time_scales.h"

namespace gins {

struct GeoWriteOptions {
  // How the track's t maps to UTC for the formats' time stamps; times below kMinAbsoluteTime have no date:
  // then GPX/KML carry no <time>/<TimeStamp> and GeoJSON only the numeric t.
  LogTimeScale time_scale = LogTimeScale::kGps;
};

// Each writes the whole document to `out` (the caller's, left open; its I/O errors are the caller's to
// check). Non-finite samples and fixes are skipped: nothing written is ever NaN.
void WriteKml(const GeoTrack& track, const GeoWriteOptions& options, std::FILE* out);
void WriteGpx(const GeoTrack& track, const GeoWriteOptions& options, std::FILE* out);
void WriteGeoJson(const GeoTrack& track, const GeoWriteOptions& options, std::FILE* out);

// How many features each writer emits for a track (the same in the three formats).
struct GeoFeatureCounts {
  int lines = 0;
  int points = 0;
};
GeoFeatureCounts CountGeoFeatures(const GeoTrack& track);

}  // namespace gins
