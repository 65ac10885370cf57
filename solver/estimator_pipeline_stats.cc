// The estimator pipeline's summary (solver/estimator_pipeline.h): its own counts and checks, each
// estimator's, and the initialisation.
#include "solver/estimator_pipeline.h"
#include "solver/summary_keys.h"

namespace gins {

nlohmann::json EstimatorPipeline::Stats() const {
  nlohmann::json j;
  namespace k = summary_keys;
  j[k::kOdomIgnoredWheelDisabled] = odom_ignored_;
  j[k::kGvelUnused] = gvel_unused_;
  MeasurementModules::ForEach([&](auto tag) {  // "baro_unused": before the initialisation, or disabled
    using Mod = typename decltype(tag)::type;
    const uint64_t n = module_unused_[MeasurementModules::IndexOf<Mod>()];
    if (n > 0) j[std::string(Mod::Record::kInfo.count_key) + "_unused"] = n;
  });
  j[k::kImuIntervalJitter] = imu_jitter_;
  j[k::kImuRateChanges] = imu_rate_changes_;
  j[k::kImuSameStamp] = imu_same_stamp_;
  j[k::kWheelIntervalJitter] = wheel_jitter_;
  j[k::kWheelGaps] = wheel_gaps_;
  j[k::kDroppedBeforeFirstFix] = pending_dropped_;
  j["standstill_updates"] = standstill_sent_;
  if (raw_feed_ || raw_.epochs > 0) j["gnss_raw"] = RawGnssStats();
  j[k::kRestStatesBeforeInitialization] = rest_sent_;
  if (!imu_warning_.empty()) j["warnings"] = {imu_warning_};
  if (sensors_.vehicle.nonholonomic) {
    const char* verdict = turn_check_.outcome() == TurnRateCheck::Outcome::kOk ? "ok" : "undecided";
    j["turn_rate_check"] = {{"verdict", verdict},
                            {"course_per_gyro", turn_check_.slope()},
                            {"correlation", turn_check_.correlation()},
                            {"turned_deg", turn_check_.turned() * kRadToDeg}};
    j["clock_check"] = {{"verdict", clock_check_.outcome() == ClockOffsetCheck::Outcome::kOk ? "ok" : "undecided"},
                        {"correlation_at_0", clock_check_.Correlation(0)}};
    if (sensors_.gnss.use_heading) {
      j["heading_check"] = {
          {"verdict", heading_check_.outcome() == HeadingCourseCheck::Outcome::kOk ? "ok" : "undecided"}};
    }
  }
  // Simulated outages as absolute [begin, end) windows, and the log's own GNSS gaps.
  nlohmann::json outages = nlohmann::json::array(), gaps = nlohmann::json::array();
  if (first_t_ >= 0.0) {
    for (const auto& [b, e] : outage_schedule_.Windows(first_t_, last_t_)) outages.push_back({b, e});
  }
  for (const auto& [b, e] : gnss_gaps_.gaps()) gaps.push_back({b, e});
  j["gnss_outages"] = {{"windows", outages},
                       {"fixes_dropped", outage_dropped_},
                       {"fixes_kept_before_initialization", outage_kept_before_init_},
                       {"log_gaps", gaps}};
  for (size_t i = 0; i < estimators_.size(); ++i) {
    const Timed& te = estimators_[i];
    if (i > 0 && !workers_.empty()) continue;  // running on its thread: its counts after Finish
    j["estimators"][te.estimator->name()] = te.estimator->Stats();
    j["estimator_time_s"][te.estimator->name()] = std::chrono::duration<double>(te.time).count();
  }
  if (init_ && init_->done()) {
    const InitResult& ir = init_->result();
    const Vec3 bg = ir.x0.bg * kRadToDeg * 3600.0;
    j["initialization"] = {{"time", ir.x0.t},
                           {"static_start", ir.static_start},
                           {"static_end", ir.static_end},
                           {"heading_source", ir.heading_source},
                           {"start", ir.start},
                           {"nonholonomic_fit", ir.nonholonomic_fit},
                           {"standstill_witness", ir.standstill_witness},
                           {"window_start", ir.window_start},
                           {"yaw_sigma_deg", ir.yaw_sigma * kRadToDeg},
                           {"roll_pitch_sigma_deg", ir.tilt_sigma * kRadToDeg},
                           {"fit_chi2_per_dof", ir.chi2_per_dof},
                           {"fit_inflation", ir.inflation},
                           {"gyro_bias_deg_h", {bg.x(), bg.y(), bg.z()}},
                           {"acc_bias_m_s2", {ir.x0.ba.x(), ir.x0.ba.y(), ir.x0.ba.z()}},
                           {"gyro_noise_deg_sqrt_h", ir.gyro_noise_density * kRadToDeg * 60.0},
                           {"acc_noise_m_s_sqrt_h", ir.acc_noise_density * 60.0}};
  }
  return j;
}

}  // namespace gins
