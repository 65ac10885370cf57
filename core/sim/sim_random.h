// The simulators' random numbers (core/sim/simulator.h, core/sim/raw_gnss.h): one engine per random source,
// each seeded from a master engine, and normals by Box–Muller from the engine's raw bits, so a seed gives the
// same draws whatever the standard library's distributions do.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

#include "core/conventions.h"

namespace gins {

class SimRng {
 public:
  explicit SimRng(uint64_t seed) : engine_(seed) {}
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }  // [0, 1)
  // Box–Muller with both uniforms drawn every time, so each normal costs exactly two engine draws.
  double Normal() {
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }
  Vec3 Normal3() { return Vec3(Normal(), Normal(), Normal()); }

 private:
  std::mt19937_64 engine_;
};

// Seed of random source `index`: the index-th draw of the master engine seeded with `seed`.
inline uint64_t DerivedSeed(uint64_t seed, int index) {
  std::mt19937_64 master(seed);
  master.discard(static_cast<unsigned long long>(index));
  return master();
}

}  // namespace gins
