#include "core/chi2.h"

#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace gins {
namespace {

// Regularised lower incomplete gamma P(a, x): series for x < a + 1, continued fraction otherwise
// (Numerical Recipes' split, which keeps both converging fast).
double RegularizedGammaP(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double log_prefix = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 500; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-15) break;
    }
    return sum * std::exp(log_prefix);
  }
  // Lentz's continued fraction for Q(a, x).
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 500; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-15) break;
  }
  return 1.0 - std::exp(log_prefix) * h;
}

}  // namespace

double Chi2Cdf(double x, int dof) { return RegularizedGammaP(0.5 * dof, 0.5 * x); }

double Chi2Gate(double probability, int dof) {
  if (!(probability > 0.0)) return std::numeric_limits<double>::infinity();
  // Each update asks again with the same few (probability, dof); the quantile's bisection costs ~10 µs, a
  // raw GNSS epoch asks several times. Per thread: the estimators may run on their own.
  thread_local std::map<std::pair<double, int>, double> known;
  const auto [it, added] = known.try_emplace({probability, dof}, 0.0);
  if (added) it->second = Chi2Quantile(probability, dof);
  return it->second;
}

double Chi2Quantile(double p, int dof) {
  double lo = 0.0, hi = 1.0;
  while (Chi2Cdf(hi, dof) < p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (Chi2Cdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace gins
