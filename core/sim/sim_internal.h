// Helpers shared by the simulator's source files. Internal to core/sim.
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>

namespace gins::sim_internal {

// Sample times may exceed the duration (or miss log_start) by round-off.
constexpr double kTimeTolerance = 1e-9;

inline void Require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("simulate: " + what);
}

inline bool FiniteNonNegative(double v) { return std::isfinite(v) && v >= 0.0; }

}  // namespace gins::sim_internal
