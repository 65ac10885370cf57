// NMEA 0183 sentences of a trajectory (GGA, RMC, GST, HDT), as GNSS receivers write them, for tools that
// read a receiver's output (mapping software, gpsd, RTKLIB's converters). `gins export` writes one epoch's
// sentences after another; the caller converts the log's clock to UTC (core/time_scales.h).
//
// Every field of a sentence is rounded once, where it is printed: a time of 59.996 s is 00.00 s of the next
// minute (and of the next day, which the RMC date then is), and 59.99999999' of arc is 00.0000000' of the
// next degree. Positions have 7 decimals of a minute (0.2 mm), so a sentence read back is within 1 cm of
// its sample: more than NMEA's 4, as RTK receivers write them. With the fields left empty here (satellites,
// HDOP) every sentence still fits NMEA's 82 characters: the longest, an RMC below 1000 kn, has 81; filling
// those fields in a GGA would take it past 82, as many RTK receivers' GGAs are.
// Nothing is written with a number that is not finite: an epoch whose time or position is not finite has no
// sentences (""), and a velocity, heading or σ that is not finite counts as absent.
#pragma once

#include <string>
#include <string_view>

#include "core/io/geo_track.h"

namespace gins {

// GGA's fix quality field.
enum class NmeaQuality { kGps = 1, kDgps = 2, kRtkFixed = 4, kRtkFloat = 5, kDeadReckoning = 6 };

struct NmeaEpoch {
  double unix_utc = 0.0;  // the epoch's UTC time (caller converts from the log's clock)
  GeoSample sample;       // position, optional velocity, heading, σ (sample.t is not used)
  NmeaQuality quality = NmeaQuality::kGps;
  std::string talker = "GN";  // two letters: GN for a multi-constellation solution, GP for GPS only
};

// Each returns one full sentence "$<talker><type>,...*HH\r\n", HH its checksum.
//
// GGA: time, position, quality; altitude is the ellipsoidal height with geoid separation 0.0 (gins has no
// geoid model: a reader adding the two gets the ellipsoidal height back). Satellites, HDOP, differential
// age and station are empty.
std::string NmeaGga(const NmeaEpoch& e);
// RMC (NMEA 2.3, with the mode indicator): status A and mode A (GPS), D (DGPS, RTK fixed and float: NMEA
// 2.3 has no RTK modes) or E (dead reckoning: status stays A, as u-blox receivers write it); speed (knots)
// and course (true, deg) over ground from v_enu's horizontal part, empty without v_enu, the course also
// empty below 0.05 m/s where it is noise; the date (ddmmyy) of the rounded time. Magnetic variation empty.
std::string NmeaRmc(const NmeaEpoch& e);
// GST: σ of latitude, longitude, altitude (m) from sigma_enu (north, east, up). With per-axis σ only, the
// error ellipse is axis-aligned: semi-major max(σe, σn), semi-minor the other, orientation 0 (along north)
// or 90 (along east). The RMS of the range residuals is empty. "" without sigma_enu.
std::string NmeaGst(const NmeaEpoch& e);
// HDT: true heading (deg, [0, 360)). "" without heading_deg.
std::string NmeaHdt(const NmeaEpoch& e);

// The checksum of the text between '$' and '*': the XOR of its characters as two upper-case hex digits.
std::string NmeaChecksum(std::string_view body);

}  // namespace gins
