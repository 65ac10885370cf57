// Line-of-sight geometry and the atmosphere's delays for pseudoranges: elevation/azimuth of a satellite from
// the receiver, the Saastamoinen troposphere on a standard atmosphere, the broadcast Klobuchar ionosphere,
// the ionosphere-free combination, and the pseudorange σ model. Values only.
#pragma once

#include <array>

#include "core/conventions.h"

namespace gins {

// Geodetic latitude, longitude (rad) and ellipsoidal height (m, WGS 84) of an ECEF point.
struct GeodeticRad {
  double lat = 0.0, lon = 0.0, h = 0.0;
};
GeodeticRad EcefToGeodeticRad(const Vec3& ecef_m);

// Azimuth (rad, clockwise from north, [0, 2π)) and elevation (rad) of `sat_ecef_m` seen from `rx_ecef_m`,
// in the local ENU frame of the receiver's geodetic position. The unit line of sight (ECEF, receiver to
// satellite) in *los if given.
struct AzEl {
  double az = 0.0, el = 0.0;
};
AzEl SatelliteAzEl(const Vec3& rx_ecef_m, const Vec3& sat_ecef_m, Vec3* los = nullptr);

// A receiver's ECEF position with its geodetic coordinates and the sines and cosines of its latitude and
// longitude (its ENU axes): worked out once per position, for every satellite seen from there.
struct ReceiverSite {
  explicit ReceiverSite(const Vec3& ecef_m);
  Vec3 ecef_m;
  GeodeticRad geo;
  double sin_lat, cos_lat, sin_lon, cos_lon;
};
AzEl SatelliteAzEl(const ReceiverSite& rx, const Vec3& sat_ecef_m, Vec3* los = nullptr);

// A standard atmosphere at height h (m, clamped to ≥ 0): pressure 1013.25·(1 − 2.2557e-5·h)^5.2568 hPa,
// temperature 15 °C − 6.5e-3·h, water vapour pressure from the relative humidity (Magnus-type formula,
// e = 6.108·rh·exp((17.15·T − 4684)/(T − 38.45)) hPa, T in K) — RTKLIB tropmodel's, for comparability.
struct Atmosphere {
  double pressure_hpa = 0.0, temperature_k = 0.0, water_vapour_hpa = 0.0;
};
Atmosphere StandardAtmosphere(double height_m, double relative_humidity = 0.7);

// Saastamoinen (1972) zenith delays (m): hydrostatic 0.0022768·P/(1 − 0.00266·cos 2φ − 0.00028·h_km),
// wet 0.002277·(1255/T + 0.05)·e. About 2.3 m hydrostatic at sea level.
struct ZenithDelay {
  double hydrostatic_m = 0.0, wet_m = 0.0;
};
ZenithDelay SaastamoinenZenith(const Atmosphere& atm, double lat_rad, double height_m);

// The slant delay (m) at elevation `el_rad`: the zenith delays times 1/sin(el), Saastamoinen's flat-layer
// mapping, as RTKLIB's SPP uses (for comparability). It overstates the delay against a modern mapping
// function (Niell) by ~1 cm at 30° and ~0.1 m at 15°, growing fast below: small against a code σ of metres
// with a mask of 10-15°. 0 below the horizon or for heights out of −100..10000 m.
double SaastamoinenSlant(double lat_rad, double height_m, double el_rad, double relative_humidity = 0.7);

// Broadcast ionosphere, IS-GPS-200 §20.3.3.5.2.5 and figure 20-4: the L1 delay (m) of a signal from
// azimuth/elevation (rad) at the receiver's geodetic lat/lon (rad) at GPS seconds of week `gps_sow`.
// alpha: s, s/sc, s/sc², s/sc³; beta: s .. s/sc³ (GPSA/GPSB of the RINEX header). Scale by (f_L1/f)² for
// another frequency.
double KlobucharL1Delay(const std::array<double, 4>& alpha, const std::array<double, 4>& beta, double lat_rad,
                        double lon_rad, double az_rad, double el_rad, double gps_sow);

// The ionosphere-free pseudorange (f1²·P1 − f2²·P2)/(f1² − f2²): first-order ionosphere removed, noise
// ≈ 3× that of P1 for L1/L5.
double IonosphereFreeCombination(double p1_m, double f1_hz, double p2_m, double f2_hz);

// Pseudorange σ (m) of a satellite at elevation el: σ² = a² + b²/sin²(el) + c²·10^(max(cn0_ref − cn0, 0)/10)
// (RTKLIB's a + b/sin(el) shape, plus a C/N0 term of its demo5 branch). Defaults a = b = 0.3 m (RTKLIB's
// code error: 100 × 0.003 m), c = 0 (off).
struct PseudorangeSigmaModel {
  double a_m = 0.3, b_m = 0.3, c_m = 0.0, cn0_ref_dbhz = 45.0;
  double Sigma(double el_rad, double cn0_dbhz) const;
};

}  // namespace gins
