// χ² distribution: the quantile used for innovation gates. Small, exact enough (1e-10 relative) for
// the degrees of freedom gins uses (1..9).
#pragma once

namespace gins {

// P(X ≤ x) for X ~ χ²(dof).
double Chi2Cdf(double x, int dof);
// The x with Chi2Cdf(x, dof) = p, for p in (0, 1).
double Chi2Quantile(double p, int dof);
// An innovation gate: the χ²(dof) quantile of `probability`, or +∞ (no gate) for probability 0, as the
// config's *.gate_probability keys mean it.
double Chi2Gate(double probability, int dof);

}  // namespace gins
