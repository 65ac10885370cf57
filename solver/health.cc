#include "solver/health.h"

#include <cstdio>

#include "solver/summary_keys.h"

namespace gins {
namespace {

uint64_t Count(const nlohmann::json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_number() ? j[key].get<uint64_t>() : 0;
}

void Worsen(Health* h, const char* verdict, const std::string& reason) {
  if (h->verdict != "failed") h->verdict = verdict;
  h->reasons.push_back(reason);
}

}  // namespace

std::string Health::Describe() const {
  std::string s = verdict;
  for (size_t i = 0; i < reasons.size(); ++i) s += (i == 0 ? ": " : "; ") + reasons[i];
  return s;
}

Health JudgeHealth(const nlohmann::json& est, uint64_t non_finite_states) {
  Health h;
  // Every problem at its own level first, then the verdict is the worst of them.
  std::vector<std::pair<const char*, std::string>> found;
  if (est.contains("gnss_position")) {
    const nlohmann::json& g = est["gnss_position"];
    const uint64_t used = Count(g, "used");
    uint64_t rejected = 0;
    if (g.contains("rejected")) {
      for (const auto& [reason, n] : g["rejected"].items()) rejected += n.get<uint64_t>();
    }
    const uint64_t offered = used + rejected;
    if (offered > 0 && rejected > 0) {
      const double share = static_cast<double>(rejected) / static_cast<double>(offered);
      char buf[128];
      std::snprintf(buf, sizeof(buf), "%llu of %llu GNSS fixes rejected (%.1f %%)",
                    static_cast<unsigned long long>(rejected), static_cast<unsigned long long>(offered),
                    100.0 * share);
      if (offered >= Health::kMinFixes && 2 * rejected > offered) {
        found.push_back({"failed", buf});
      } else if (share > Health::kDegradedShare) {
        found.push_back({"degraded", buf});
      }
    }
  }
  const uint64_t resets =
      est.contains(summary_keys::kWatchdog) ? Count(est[summary_keys::kWatchdog], summary_keys::kWatchdogCount) : 0;
  if (resets > 0) {
    found.push_back({resets >= Health::kFailedResets ? "failed" : "degraded",
                     std::to_string(resets) + " watchdog re-initialisation" + (resets > 1 ? "s" : "")});
  }
  if (const uint64_t n = Count(est, "covariance_failures"); n > 0) {
    found.push_back({"degraded", std::to_string(n) + " covariance recoveries failed"});
  }
  if (est.contains("batch") && est["batch"].contains("covariance_ok") && !est["batch"]["covariance_ok"].get<bool>()) {
    found.push_back({"degraded", "the whole-log solution has no covariances"});
  }
  if (non_finite_states > 0) {
    found.push_back({"degraded", std::to_string(non_finite_states) + " states not finite, not written"});
  }
  for (const auto& [level, reason] : found) {
    if (std::string(level) == "failed") Worsen(&h, "failed", reason);
  }
  for (const auto& [level, reason] : found) {
    if (std::string(level) == "degraded") Worsen(&h, "degraded", reason);
  }
  return h;
}

}  // namespace gins
