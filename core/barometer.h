// The barometer (BARO records, docs/formats.md §3): an altitude above the WGS 84 ellipsoid from a barometric
// altimeter, a measurement module (core/measurement_module.h). The altitude must already be referenced to
// the ellipsoid (a barometer's own zero drifts with the weather: calibrate it against GNSS first, and state
// a σ that covers what is left of that offset); its bias is not a state.
//
// Model, of the IMU's position p_w at the record's time:
//   h(p_w) = h_0 + p_u + p_e² / (2 (N + h_0)) + p_n² / (2 (M + h_0))
// the height above the ellipsoid of a point of w (ENU at the origin, height h_0) to second order in its
// distance from the origin, N and M the prime-vertical and meridian radii there (the ellipsoid falls away
// under a tangent plane by d²/2R: 8 cm at 1 km, 7.8 m at 10 km; what the second order leaves is below
// d³/R², 2.5 mm at 10 km). Residual r = (h(p_w) − alt) / σ.
#pragma once

#include <GeographicLib/Constants.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <iterator>
#include <optional>
#include <string>

#include "core/geodesy.h"
#include "core/measurement_module.h"
#include "core/option_spec.h"
#include "core/preintegration.h"

namespace gins {

struct BarometerModule {
  static constexpr const char* kName = "barometer";

  // BARO t alt_m [sigma_m]
  struct Record {
    double t = 0.0;
    double alt_m = 0.0;    // above the WGS 84 ellipsoid, at the IMU
    double sigma_m = 0.0;  // 1-σ, m; 0: not logged (barometer.sigma_m)

    static constexpr const char* kFields[] = {"t", "alt", "sigma"};
    static constexpr RecordTypeInfo kInfo = {"BARO", "barometer", "baro", kFields, std::size(kFields), 2, true};
    static constexpr double kMinAlt = -1000.0, kMaxAlt = 1e5, kMaxSigma = 1e4;  // m, exclusive: as a GNSS fix's

    static std::string Absurd(const double* v, size_t n) {
      if (!(v[1] > kMinAlt && v[1] < kMaxAlt)) return "field 3 (alt) " + Num(v[1]) + " m, outside (-1000, 1e+05)";
      if (n == 3 && !(v[2] > 0.0 && v[2] < kMaxSigma)) {
        return "field 4 (sigma) " + Num(v[2]) + " m, σ must be in (0, 1e+04)";
      }
      return {};
    }
    static std::string Num(double v) {  // as the reader's messages write numbers
      char text[32];
      std::snprintf(text, sizeof(text), "%g", v);
      return text;
    }
    static void Fill(const double* v, size_t n, Record* r) {
      r->t = v[0];
      r->alt_m = v[1];
      r->sigma_m = n == 3 ? v[2] : 0.0;
    }
    static size_t Values(const Record& r, double* v) {
      v[0] = r.t, v[1] = r.alt_m, v[2] = r.sigma_m;
      return r.sigma_m > 0.0 ? 3 : 2;
    }
  };

  struct Options {
    static constexpr const char* kSection = "barometer";
    static constexpr auto kKeys = [](auto& v, auto& o) {  // o: Options
      v.Boolean("enabled", o.enabled);
      v.Number("sigma_m", o.sigma, kNoUnit, Positive());
      v.Number("min_sigma_m", o.min_sigma, kNoUnit, Positive());
      v.Number("gate_probability", o.gate_probability, kNoUnit, GateProbability());
    };
    bool enabled = true;
    double sigma = 1.0;              // m: for records without their own σ
    double min_sigma = 0.1;          // m: a logged σ is raised to at least this
    double gate_probability = 0.999;
  };

  struct Measurement {
    double t = 0.0;
    double height = 0.0;  // alt − h_0, m
    double sigma = 1.0;   // m
    double half_inv_radius_e = 0.0, half_inv_radius_n = 0.0;  // 1 / 2(N + h_0), 1 / 2(M + h_0), 1/m
  };

  struct Model {
    static constexpr int kResidualDim = 1;
    Measurement m;
    template <typename T>
    void operator()(const PredictedKinematics<T>& k, T* residual) const {
      const T h = k.p.z() + k.p.x() * k.p.x() * m.half_inv_radius_e + k.p.y() * k.p.y() * m.half_inv_radius_n;
      residual[0] = (h - m.height) / m.sigma;
    }
  };

  static std::optional<Measurement> ToMeasurement(const Record& r, const Options& o, const LocalEnuFrame& w) {
    if (!o.enabled) return std::nullopt;
    const double a = GeographicLib::Constants::WGS84_a();
    const double f = GeographicLib::Constants::WGS84_f();
    const double e2 = f * (2.0 - f);
    const double s = std::sin(w.origin().lat_deg * kDegToRad);
    const double d = 1.0 - e2 * s * s;
    const double N = a / std::sqrt(d);
    const double M = a * (1.0 - e2) / (d * std::sqrt(d));
    Measurement m;
    m.t = r.t;
    m.height = r.alt_m - w.origin().alt_m;
    m.sigma = r.sigma_m > 0.0 ? std::max(r.sigma_m, o.min_sigma) : o.sigma;
    m.half_inv_radius_e = 0.5 / (N + w.origin().alt_m);
    m.half_inv_radius_n = 0.5 / (M + w.origin().alt_m);
    return m;
  }
  static Model ModelOf(const Measurement& m, const Options& /*o*/) { return Model{m}; }
};

}  // namespace gins
