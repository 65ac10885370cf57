// Line of sight, troposphere, ionosphere, pseudorange σ (core/gnss_atmosphere.h).
#include "core/gnss_atmosphere.h"

#include <GeographicLib/Geocentric.hpp>
#include <algorithm>
#include <cmath>

namespace gins {

GeodeticRad EcefToGeodeticRad(const Vec3& ecef_m) {
  GeodeticRad g;
  GeographicLib::Geocentric::WGS84().Reverse(ecef_m.x(), ecef_m.y(), ecef_m.z(), g.lat, g.lon, g.h);
  g.lat *= kDegToRad;
  g.lon *= kDegToRad;
  return g;
}

ReceiverSite::ReceiverSite(const Vec3& ecef) : ecef_m(ecef), geo(EcefToGeodeticRad(ecef)) {
  sin_lat = std::sin(geo.lat);
  cos_lat = std::cos(geo.lat);
  sin_lon = std::sin(geo.lon);
  cos_lon = std::cos(geo.lon);
}

AzEl SatelliteAzEl(const Vec3& rx_ecef_m, const Vec3& sat_ecef_m, Vec3* los) {
  return SatelliteAzEl(ReceiverSite(rx_ecef_m), sat_ecef_m, los);
}

AzEl SatelliteAzEl(const ReceiverSite& rx, const Vec3& sat_ecef_m, Vec3* los) {
  const Vec3 d = (sat_ecef_m - rx.ecef_m).normalized();
  const double sp = rx.sin_lat, cp = rx.cos_lat, sl = rx.sin_lon, cl = rx.cos_lon;
  const double east = -sl * d.x() + cl * d.y();
  const double north = -sp * cl * d.x() - sp * sl * d.y() + cp * d.z();
  const double up = cp * cl * d.x() + cp * sl * d.y() + sp * d.z();
  AzEl out;
  out.el = std::asin(std::clamp(up, -1.0, 1.0));
  out.az = std::atan2(east, north);
  if (out.az < 0.0) out.az += 2.0 * kPi;
  if (los) *los = d;
  return out;
}

Atmosphere StandardAtmosphere(double height_m, double relative_humidity) {
  const double h = std::max(height_m, 0.0);
  Atmosphere a;
  a.pressure_hpa = 1013.25 * std::pow(1.0 - 2.2557e-5 * h, 5.2568);
  a.temperature_k = 15.0 - 6.5e-3 * h + 273.16;  // 273.16 as RTKLIB (0.01 K: 0.02 mm of wet delay)
  a.water_vapour_hpa =
      6.108 * relative_humidity * std::exp((17.15 * a.temperature_k - 4684.0) / (a.temperature_k - 38.45));
  return a;
}

ZenithDelay SaastamoinenZenith(const Atmosphere& atm, double lat_rad, double height_m) {
  ZenithDelay z;
  z.hydrostatic_m =
      0.0022768 * atm.pressure_hpa / (1.0 - 0.00266 * std::cos(2.0 * lat_rad) - 0.00028 * height_m / 1e3);
  z.wet_m = 0.002277 * (1255.0 / atm.temperature_k + 0.05) * atm.water_vapour_hpa;
  return z;
}

double SaastamoinenSlant(double lat_rad, double height_m, double el_rad, double relative_humidity) {
  if (height_m < -100.0 || height_m > 1e4 || el_rad <= 0.0) return 0.0;
  const double h = std::max(height_m, 0.0);
  const ZenithDelay z = SaastamoinenZenith(StandardAtmosphere(h, relative_humidity), lat_rad, h);
  return (z.hydrostatic_m + z.wet_m) / std::sin(el_rad);
}

double KlobucharL1Delay(const std::array<double, 4>& alpha, const std::array<double, 4>& beta, double lat_rad,
                        double lon_rad, double az_rad, double el_rad, double gps_sow) {
  constexpr double kC = 299792458.0;
  if (el_rad <= 0.0) return 0.0;
  // Figure 20-4 works in semicircles (sc).
  const double e = el_rad / kPi;
  const double psi = 0.0137 / (e + 0.11) - 0.022;  // Earth-centred angle to the pierce point
  double phi_i = lat_rad / kPi + psi * std::cos(az_rad);
  phi_i = std::clamp(phi_i, -0.416, 0.416);
  const double lambda_i = lon_rad / kPi + psi * std::sin(az_rad) / std::cos(phi_i * kPi);
  const double phi_m = phi_i + 0.064 * std::cos((lambda_i - 1.617) * kPi);  // geomagnetic latitude
  double t = std::fmod(4.32e4 * lambda_i + gps_sow, 86400.0);                // local time at the pierce point
  if (t < 0.0) t += 86400.0;
  const double f = 1.0 + 16.0 * std::pow(0.53 - e, 3.0);  // slant factor
  double amp = alpha[0] + phi_m * (alpha[1] + phi_m * (alpha[2] + phi_m * alpha[3]));
  double per = beta[0] + phi_m * (beta[1] + phi_m * (beta[2] + phi_m * beta[3]));
  amp = std::max(amp, 0.0);
  per = std::max(per, 72000.0);
  const double x = 2.0 * kPi * (t - 50400.0) / per;
  const double x2 = x * x;
  const double delay_s = std::abs(x) < 1.57 ? f * (5e-9 + amp * (1.0 - x2 / 2.0 + x2 * x2 / 24.0)) : f * 5e-9;
  return kC * delay_s;
}

double IonosphereFreeCombination(double p1_m, double f1_hz, double p2_m, double f2_hz) {
  const double g1 = f1_hz * f1_hz, g2 = f2_hz * f2_hz;
  return (g1 * p1_m - g2 * p2_m) / (g1 - g2);
}

double PseudorangeSigmaModel::Sigma(double el_rad, double cn0_dbhz) const {
  const double s = std::max(std::sin(el_rad), 0.05);  // below 3°: as at 3°
  double var = a_m * a_m + b_m * b_m / (s * s);
  if (c_m > 0.0 && cn0_dbhz > 0.0) var += c_m * c_m * std::pow(10.0, std::max(cn0_ref_dbhz - cn0_dbhz, 0.0) / 10.0);
  return std::sqrt(var);
}

}  // namespace gins
