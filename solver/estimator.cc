#include "solver/estimator.h"

namespace gins {

namespace {
constexpr size_t kMaxListedTimes = 100;
}

void MeasurementCounts::Reject(const std::string& reason, double t) {
  ++rejected[reason];
  if (rejected_times.size() < kMaxListedTimes) rejected_times.push_back(t);
}

nlohmann::json MeasurementCounts::ToJson() const {
  nlohmann::json j;
  j["used"] = used;
  j["rejected"] = nlohmann::json::object();
  for (const auto& [k, v] : rejected) j["rejected"][k] = v;
  j["rejected_times"] = rejected_times;
  return j;
}

bool GnssWatchdog::Watch(double t, bool accepted) {
  if (accepted) {
    Clear();
    return false;
  }
  if (first_reject_t_ < 0.0) first_reject_t_ = t;
  ++rejects_;
  return options_.enabled && rejects_ >= kMinRejects && t - first_reject_t_ >= options_.max_reject;
}

void GnssWatchdog::Reset(double t, const std::string& reason) {
  Clear();
  ++count_;
  if (resets_.size() < kMaxListedTimes) resets_.push_back({t, reason});
}

nlohmann::json GnssWatchdog::ToJson() const {
  nlohmann::json resets = nlohmann::json::array();
  for (const Event& r : resets_) resets.push_back({{"time", r.t}, {"reason", r.reason}});
  return {{"resets", resets}, {"count", count_}};
}

}  // namespace gins
