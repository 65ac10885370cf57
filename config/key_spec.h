// What a config key's value means, shared by the YAML reader and writer (config/config_keys.h declares the
// keys): the unit the user writes (Unit), the values allowed (Check), the names a choice key accepts
// (Choices) and the named IMU axis mappings. Internal to config/.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/conventions.h"

namespace gins::config_internal {

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

// Empty when v passes, else the reason.
std::string Violation(const Check& c, double v);

// Every key may be left out (keeping its default) except a few in items of a list (a segment's duration_s).
enum class Presence { kOptional, kRequired };

// ---------------------------------------------------------------------------------------------------------
// Choice keys: the names a key accepts, in the order error messages list them, and the value each stands for.

template <class T>
using Choices = std::vector<std::pair<std::string, T>>;

// A string key whose value is its own name (smoother.linear_solver).
inline Choices<std::string> Names(const std::vector<std::string>& names) {
  Choices<std::string> choices;
  for (const std::string& n : names) choices.emplace_back(n, n);
  return choices;
}

// ---------------------------------------------------------------------------------------------------------
// Axis mappings (imu.axes): R_b_imu takes a vector in the logged axes into the body FLU frame.

struct NamedAxes {
  const char* name;
  Mat3 R_b_imu;
};

std::vector<NamedAxes> KnownAxes();

// ---------------------------------------------------------------------------------------------------------
// Text <-> number, locale-independent (a host program's locale must not turn "0.5" into an error).

std::string Text(double v, int precision = 6);
bool ParseDouble(const std::string& s, double* v);

// ---------------------------------------------------------------------------------------------------------
// Keys that gins once read and no longer does. A config that sets one fails like an unknown key, but with
// why it went and what replaces it: a key accepted and ignored would let a user tune a setting that does
// nothing.

struct RemovedKey {
  const char* path;
  const char* reason;
};

inline constexpr RemovedKey kRemovedKeys[] = {
    {"smoother.gnss_loss_scale",
     "removed key: the smoother's GNSS factors carry a Huber loss whose corner is the gate "
     "(gnss.gate_probability), so every fix the gate accepts keeps full weight; delete the line"},
};

}  // namespace gins::config_internal
