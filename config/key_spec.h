// What a config key's value means, shared by the YAML reader and writer (config/config_keys.h declares the
// keys): the unit the user writes and the values allowed (Unit, Check: core/option_spec.h), the names a
// choice key accepts (Choices) and the named IMU axis mappings. Internal to config/.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/conventions.h"
#include "core/option_spec.h"  // Unit, Check: shared with the measurement modules' keys

namespace gins::config_internal {

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
