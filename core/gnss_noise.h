// Time-correlated GNSS position errors (gnss.error_correlation_s).
//
// A receiver's position errors are not independent from one fix to the next:
// atmosphere, multipath and the receiver's own tracking filter make a
// single-point solution wander slowly, so at 10-20 Hz successive fixes repeat
// much the same error. Weighing each as independent with its stated σ makes the
// estimators far too sure of the mean of a run of fixes (NEES many times its
// dimension) and lets the wander pull the attitude.
//
// Model: each axis' error is a first-order Gauss–Markov process with
// correlation time τ and stationary σ, sampled every Δt: e_k = ρ·e_{k−1} +
// √(1−ρ²)·σ·n_k, ρ = exp(−Δt/τ). The mean of N such fixes has variance
// σ²/N·(1+ρ)/(1−ρ) (for N ≫ 1), as if only N·(1−ρ)/(1+ρ) of them were
// independent. The estimators keep treating fixes as independent but inflate
// each σ by
//   k = √((1+ρ)/(1−ρ))
// so that a run of fixes carries the information it really has. τ = 0 (white
// errors) gives k = 1; a fix after a gap much longer than τ is nearly
// independent and keeps its σ.
#pragma once

#include <algorithm>
#include <cmath>

namespace gins {

// The σ factor k for a fix dt seconds after the previous one (+∞: the first),
// with correlation time tau (s; ≤ 0: white). A fix stamped with its
// predecessor's time counts as 1 ms later.
inline double CorrelatedNoiseInflation(double dt, double tau) {
  if (!(tau > 0.0)) return 1.0;
  const double rho = std::exp(-std::max(dt, 1e-3) / tau);
  return std::sqrt((1.0 + rho) / (1.0 - rho));
}

}  // namespace gins
