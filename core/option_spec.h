// What a config key's value means, as every key declares it (config/config_keys.h; a measurement module's own
// keys, core/measurement_module.h): the unit the user writes (Unit) and the values allowed (Check). The YAML
// reader and writer (config/) apply them.
#pragma once

#include "core/conventions.h"

namespace gins {

// ---------------------------------------------------------------------------------------------------------
// Units. A YAML number is in the unit its key names; to_si converts it. Each to_si performs the operations
// in the same order as the in-class defaults of the option structs (e.g. v * kDegToRad / 60.0), so
// default.yaml loads to bit-identical doubles. from_si is only a first guess used when writing (FormatNumber).

struct Unit {
  double (*to_si)(double);
  double (*from_si)(double);
};

inline double Same(double v) { return v; }
inline double DegToRad(double v) { return v * kDegToRad; }
inline double RadToDeg(double x) { return x * kRadToDeg; }
inline double DegSqrtHToSi(double v) { return v * kDegToRad / 60.0; }  // deg/√h → rad/s/√Hz
inline double SiToDegSqrtH(double x) { return x * kRadToDeg * 60.0; }
inline double PerSqrtHToSi(double v) { return v / 60.0; }  // m/s/√h → m/s²/√Hz; m/s²/√h → m/s²/√s
inline double SiToPerSqrtH(double x) { return x * 60.0; }
inline double DegHSqrtHToSi(double v) { return v * kDegToRad / 3600.0 / 60.0; }  // deg/h/√h → rad/s/√s
inline double SiToDegHSqrtH(double x) { return x * kRadToDeg * 3600.0 * 60.0; }
inline double DegHToSi(double v) { return v * kDegToRad / 3600.0; }  // deg/h → rad/s
inline double SiToDegH(double x) { return x * kRadToDeg * 3600.0; }
inline double CompassToYaw(double v) { return CompassDegToEnuYaw(v); }  // deg clockwise from north → ENU yaw
inline double YawToCompass(double x) { return EnuYawToCompassDeg(x); }

constexpr Unit kNoUnit{Same, Same};
constexpr Unit kDeg{DegToRad, RadToDeg};
constexpr Unit kDegPerSqrtH{DegSqrtHToSi, SiToDegSqrtH};
constexpr Unit kPerSqrtH{PerSqrtHToSi, SiToPerSqrtH};
constexpr Unit kDegPerHPerSqrtH{DegHSqrtHToSi, SiToDegHSqrtH};
constexpr Unit kDegPerH{DegHToSi, SiToDegH};
constexpr Unit kCompassDeg{CompassToYaw, YawToCompass};

// ---------------------------------------------------------------------------------------------------------
// Range checks, applied to the value in the user's unit (so the message quotes what the user wrote).

struct Check {
  enum class Kind { kAny, kPositive, kNonNegative, kGate, kFraction, kProbability, kWithin };
  Kind kind = Kind::kAny;
  double lo = 0.0;
  double hi = 0.0;
};

constexpr Check AnyValue() { return {}; }
constexpr Check Positive() { return {Check::Kind::kPositive}; }
constexpr Check NonNegative() { return {Check::Kind::kNonNegative}; }
constexpr Check GateProbability() { return {Check::Kind::kGate}; }     // 0 = off, else in (0, 1)
constexpr Check Fraction() { return {Check::Kind::kFraction}; }        // [0, 1]
constexpr Check Probability() { return {Check::Kind::kProbability}; }  // [0, 1)
constexpr Check Within(double lo, double hi) { return {Check::Kind::kWithin, lo, hi}; }

}  // namespace gins
