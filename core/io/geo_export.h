// `gins export`'s conversions (docs/formats.md §5.7): any trajectory gins reads or writes (a TUM file, a
// states CSV, a geodetic track CSV, a truth CSV) as one geo-referenced track, and that track as a geodetic
// CSV, NMEA sentences or a TUM file in a chosen frame. The map formats are core/io/geo_formats.h.
#pragma once

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "core/io/geo_track.h"
#include "core/io/nmea_sentences.h"
#include "core/io/trajectory_reader.h"
#include "core/time_scales.h"

namespace gins {

// A trajectory read for export, in the ENU frame at `trajectory.origin`.
struct ExportSource {
  Trajectory trajectory;
  std::string kind;          // "tum", "states", "lla" or "truth": what the file was
  bool has_attitude = true;  // false for a geodetic track CSV (positions only)
};

// Reads `path`, telling the kinds apart by their first line: a truth CSV's "t,lat,lon,alt,..." header, a
// geodetic track's "t,lat_deg,lon_deg,height_m[,...]", a states CSV's header, else a TUM file. Ours carry
// their origin; a foreign TUM file needs `origin` (else InputError). Throws InputError naming file and line.
ExportSource ReadExportSource(const std::string& path, const std::optional<GeodeticPoint>& origin);

// A sample as a geodetic point with the velocity and heading in the local ENU frame at the point (the
// heading only where the attitude and its yaw are known), and the σ, each where the source has it.
struct SampleContent {
  bool velocity = false, attitude = false, sigma = false;
};
GeoSample ToGeoSample(const LocalEnuFrame& frame, const TrajectorySample& s, const SampleContent& content);
GeoTrack ToGeoTrack(const ExportSource& source, const std::string& name);

// The geodetic track CSV (the _lla.csv of a run: "t,lat_deg,lon_deg,height_m,sigma_e_m,sigma_n_m,sigma_u_m";
// without σ columns when the source has none).
void WriteGeodeticCsv(const GeoTrack& track, std::FILE* out);

// The trajectory as a TUM file (with our origin comment) in the ENU frame at `origin`; needs the attitude.
void WriteTumInFrame(const ExportSource& source, const GeodeticPoint& origin, std::FILE* out);

struct NmeaExportOptions {
  double rate_hz = 1.0;  // epochs per second, on the grid of whole multiples of 1/rate_hz; 0 = every sample
  LogTimeScale time_scale = LogTimeScale::kGps;
  bool gst = true;  // GST with the σ, where the track has them
  bool hdt = true;  // HDT with the heading, where it is known
};
// The GGA quality of an epoch: dead reckoning inside a no-fix interval, else from the horizontal 1-σ
// (≤ 5 cm: 4, RTK fixed; ≤ 0.5 m: 5, RTK float; else 1), 1 without σ (docs/formats.md §5.7).
NmeaQuality QualityOf(const std::vector<GeoInterval>& no_fix, const GeoSample& s);
// The epochs as GGA and RMC (+ GST, HDT) sentences, CR LF ended. Refuses (InputError) a track with a time
// that is not absolute (HasDate): NMEA carries the UTC time of day and RMC the date.
void WriteNmea(const GeoTrack& track, const NmeaExportOptions& options, std::FILE* out);
// One epoch's sentences (the time scale and sentence choice of `options`; its rate is the caller's).
void WriteNmeaEpoch(const GeoSample& s, NmeaQuality quality, const NmeaExportOptions& options, std::FILE* out);
// The epochs of the grid WriteNmea writes: the first sample at or after each multiple of 1/rate_hz.
bool OnNmeaGrid(double t, double rate_hz, double* next_t);

}  // namespace gins
