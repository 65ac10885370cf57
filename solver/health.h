// A health verdict per estimator (docs/robustness.md, "Health"), from its counts: ok, degraded or failed, and
// why. On the console after a run and in summary.json's "health"; `gins run --strict` exits 3 unless every
// estimator is ok (fleets: a run that looks like a good one but is not fails its job).
//   failed    most GNSS fixes rejected (over half of those offered, at least kMinFixes of them): the
//             trajectory is not held by the GNSS; or the watchdog re-initialised the estimator again and
//             again (kFailedResets times or more).
//   degraded  more than kDegradedShare of the fixes rejected (one in twenty: outliers, a σ too small for the
//             receiver, or an estimate the fixes disagree with); any watchdog re-initialisation; a covariance
//             the smoother could not recover, a whole-log solution without covariances; states dropped as
//             not finite.
//   ok        none of these.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace gins {

struct Health {
  static constexpr double kDegradedShare = 0.05;
  static constexpr uint64_t kMinFixes = 10;
  static constexpr uint64_t kFailedResets = 3;

  std::string verdict = "ok";  // "ok" | "degraded" | "failed"
  std::vector<std::string> reasons;

  bool ok() const { return verdict == "ok"; }
  nlohmann::json ToJson() const { return {{"verdict", verdict}, {"reasons", reasons}}; }
  // One line: "degraded: 21 of 199 GNSS fixes rejected (10.6 %)".
  std::string Describe() const;
};

// est: one estimator's Stats() (summary.json's estimators.<name>); non_finite_states: its outputs' states
// dropped as not finite.
Health JudgeHealth(const nlohmann::json& est, uint64_t non_finite_states = 0);

}  // namespace gins
