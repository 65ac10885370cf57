// The estimator pipeline (the API's Session runs one) turns raw log records into estimator input: axis
// mapping of the IMU, pulses to wheel speed, geodetic fixes to the world frame (its origin fixed at the
// configured point or the first fix), initialisation (core/initializer.h), then the same time-ordered stream
// to every estimator. `gins run` feeds it through the API from a log file; the end-to-end tests feed it from
// the simulator.
#pragma once

#include <array>
#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/geodesy.h"
#include "core/clock_checks.h"
#include "core/imu_checks.h"
#include "core/eval/gnss_outages.h"
#include "core/io/log_record.h"
#include "core/measurements.h"
#include "core/sensors.h"
#include "core/standstill_detector.h"
#include "core/initializer.h"
#include "solver/estimator.h"
#include "solver/raw_gnss_feed.h"

namespace gins {

// A run that cannot produce a trajectory (no standstill, no GNSS, ...). what() is one line.
class RunError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class EstimatorPipeline {
 public:
  // The sensors, and the initialisation's and the standstill detector's settings (the estimators take
  // their own sections).
  EstimatorPipeline(const SensorOptions& sensors, const InitOptions& init, const StandstillOptions& standstill);
  ~EstimatorPipeline();

  void AddEstimator(std::unique_ptr<Estimator> estimator);
  // Runs every estimator after the first on a thread of its own (before the first record; with one
  // estimator it changes nothing). The estimators share nothing and each sees the same records in the same
  // order, so every stream is what the sequential run gives, bit for bit; their callbacks then come from
  // those threads (one thread per estimator, so one stream's states still come in order).
  void SetParallel(bool parallel) { parallel_ = parallel; }
  // Stops the estimators' threads now, dropping what they have not run (a run abandoned on an error: the
  // owner of their callbacks calls it before it goes away). The destructor does it too.
  void CancelThreads();

  void AddImu(const ImuSample& raw);
  void AddWheel(const WheelRecord& wheel);
  void AddGnss(const GnssRecord& fix);
  void AddGnssVelocity(const GnssVelocityRecord& vel);
  // Raw GNSS epochs (solver/raw_gnss_feed.h): from a feed, merged into the records by time (each Add* first
  // takes the feed's epochs dated up to its record's time, on GPS time: the tag less the receiver clock of
  // the epoch's fix, or of the last fix; Finish the rest), or given one by one, in time order. Each epoch's
  // single-point fix sets the world frame and initialises like a fix; then the epoch goes to every
  // estimator (Estimator::Add), with that fix when it has one (estimator_pipeline_raw.cc).
  void SetRawGnssFeed(std::unique_ptr<RawGnssFeed> feed);
  void AddRawGnss(RawGnssMeasurement m);
  // A measurement module's record (core/measurement_module.h): in w, to every estimator once initialised;
  // before the world frame, before the initialisation, or with the module disabled, counted and dropped.
  template <typename R>
  void AddModuleRecord(const R& r);
  // A log's record (or a simulated one) to the Add* of its type: the one dispatch before the estimators.
  void Add(const LogRecord& r);
  // End of the data: flushes the estimators. Throws RunError if initialisation never completed.
  void Finish();

  bool initialized() const { return initialized_; }
  const std::optional<LocalEnuFrame>& frame() const { return frame_; }
  const InitResult& init_result() const { return init_->result(); }
  double g_norm() const { return g_norm_; }
  // Why there is no solution yet (for error messages).
  std::string Diagnosis() const;
  // Seconds since the first record; for the initialisation time-out.
  double elapsed() const { return first_t_ < 0.0 ? 0.0 : last_t_ - first_t_; }
  double first_time() const { return first_t_; }
  double last_time() const { return last_t_; }

  nlohmann::json Stats() const;

 private:
  void Touch(double t);
  void EnsureInitializer();
  // A fix in w to the initialiser or the estimators (with its raw epoch, if it comes from one).
  void UseFix(const GnssRecord& g, const RawGnssMeasurement* raw);
  void DrainRawGnss(double t) {
    if (raw_feed_ && !draining_raw_) DrainRawFeed(t);
  }
  void DrainRawFeed(double t);
  void FinishRawGnss();
  nlohmann::json RawGnssStats() const;
  std::unique_ptr<RawGnssFeed> raw_feed_;
  bool draining_raw_ = false;
  // An epoch with its single-point fix, dated on GPS time (m.t), waiting for the records to reach it.
  struct PreparedRawGnss {
    RawGnssMeasurement m;
    SppSolution sol;
  };
  PreparedRawGnss PrepareRawGnss(RawGnssMeasurement m);
  void UseRawGnss(PreparedRawGnss p);
  std::deque<PreparedRawGnss> raw_queue_;
  std::optional<double> last_clock_m_;  // the receiver clock of the last fix (× c, m)
  struct RawCounts {
    uint64_t epochs = 0, before_log = 0, in_outage = 0, without_fix = 0, without_velocity = 0, used_before_init = 0;
    std::map<std::string, uint64_t> fix_failures;  // the single-point fix's reason
  };
  RawCounts raw_;
  // Inter-system biases (RawGnssMeasurement::inter_system_bias): Welford's mean and spread of each system's
  // clock less GPS's (else the first system's) over the single-point fixes.
  struct BiasMean {
    uint64_t n = 0;
    double mean = 0.0, m2 = 0.0;
  };
  std::map<GnssSystem, BiasMean> isb_;
  std::optional<GnssSystem> isb_reference_;
  void TrackInterSystemBias(const SppSolution& sol, RawGnssMeasurement* m);
  std::optional<Vec3> last_spp_ecef_;
  // Hands a copy of the measurement to every estimator (a member function of Estimator taking it).
  template <typename M>
  void Dispatch(void (Estimator::*add)(const M&), const M& m);
  void DispatchTask(const std::function<void(Estimator&)>& task);
  void StopWorkers();
  struct Worker;
  bool parallel_ = false;
  std::vector<std::unique_ptr<Worker>> workers_;  // estimators_[i + 1] runs on workers_[i] when parallel

  SensorOptions sensors_;
  InitOptions init_options_;
  StandstillOptions standstill_options_;
  std::optional<LocalEnuFrame> frame_;
  double g_norm_ = 0.0;
  EarthModel earth_;  // once the world frame exists
  std::unique_ptr<Initializer> init_;
  bool initialized_ = false;
  struct Timed {
    std::unique_ptr<Estimator> estimator;
    std::chrono::steady_clock::duration time{};
    template <typename F>
    void Call(F&& f) {  // f(*estimator), its time counted
      const auto t0 = std::chrono::steady_clock::now();
      f(*estimator);
      time += std::chrono::steady_clock::now() - t0;
    }
  };
  std::vector<Timed> estimators_;
  // Records before the first fix (no world frame yet) wait here; bounded.
  std::vector<ImuSample> pending_imu_;
  std::vector<WheelMeasurement> pending_wheel_;
  uint64_t pending_dropped_ = 0, odom_ignored_ = 0;
  // GNSS velocities: the local frame of the last fix turns them into w (it differs from w by distance /
  // Earth radius); before initialisation they go to the initialiser; those before the first fix, in a
  // simulated outage or disabled are counted.
  std::optional<GeodeticPoint> last_fix_geo_;
  std::optional<double> last_fix_t_;  // the previous fix's time (gnss.error_correlation_s)
  uint64_t gvel_unused_ = 0;
  std::array<uint64_t, MeasurementModules::kSize> module_unused_{};  // by module
  // Wheel records: the previous one's time (its spacing is the counting interval), jitter and gaps.
  WheelMeasurement WheelFromOdom(const WheelRecord& o);
  std::optional<double> last_wheel_t_;
  uint64_t wheel_jitter_ = 0, wheel_gaps_ = 0;
  double first_t_ = -1.0, last_t_ = 0.0;
  // IMU sample spacing, for the summary (the estimators integrate each interval as stamped, and count the
  // gaps): an interval more than 10 % off the nominal one is jitter; ten in a row that agree on a new
  // interval are a rate change, which becomes the nominal.
  void WatchImuInterval(double t);
  std::optional<double> last_imu_t_;
  double imu_nominal_dt_ = 0.0, imu_candidate_dt_ = 0.0;
  int imu_candidate_runs_ = 0;
  uint64_t imu_jitter_ = 0, imu_rate_changes_ = 0, imu_same_stamp_ = 0;

  // States at rest before initialisation (Initializer::RestStates), to every estimator. The newest is held
  // back until a later one comes: at the initialisation it is dropped if the estimators start at its time.
  void SendRestStates();
  void FlushRestState(double init_t);
  std::vector<RestState> rest_scratch_;
  std::optional<RestState> rest_held_;
  double last_rest_t_ = -1e300;
  uint64_t rest_sent_ = 0;

  // The IMU's units and axes from its first records (core/imu_checks.h): refused with the reason, or warned.
  ImuAxesAndUnitsCheck imu_check_;
  TurnRateCheck turn_check_;  // for a car (vehicle.nonholonomic): the gyro against the GNSS track's turns
  HeadingCourseCheck heading_check_;  // and the dual-antenna heading against the track's course
  ClockOffsetCheck clock_check_;      // and the track's accelerations against the IMU's, at whole-second lags
  std::string imu_warning_;

  // Standstill detection (core/standstill_detector.h), fed from the initialiser's start; after
  // initialisation a StandstillMeasurement goes to every estimator every 0.1 s while the vehicle stands.
  void DetectStandstill(double t);
  std::unique_ptr<StandstillDetector> standstill_;
  double standing_since_ = -1.0;         // start of the current standstill (< 0: moving)
  double last_standstill_sent_ = -1e300;
  uint64_t standstill_sent_ = 0;

  // Simulated GNSS outages (gnss.outages_s, gnss.periodic_outages_s): fixes inside a window are dropped
  // once initialised; in-window fixes before that are kept (initialisation needs them) and counted. Gaps
  // in the log's own GNSS stream are recorded too. Both go into Stats()["gnss_outages"].
  bool DropForSimulatedOutage(double t);
  GnssOutageSchedule outage_schedule_{sensors_.gnss.outages, sensors_.gnss.periodic_outages.first_start,
                                      sensors_.gnss.periodic_outages.duration, sensors_.gnss.periodic_outages.period};
  GnssGapTracker gnss_gaps_;
  uint64_t outage_dropped_ = 0, outage_kept_before_init_ = 0;
};

template <typename R>
void EstimatorPipeline::AddModuleRecord(const R& r) {
  constexpr size_t i = MeasurementModules::IndexOfRecord<R>();
  using Mod = MeasurementModules::At<i>;
  DrainRawGnss(r.t);
  Touch(r.t);
  std::optional<typename Mod::Measurement> m;
  if (initialized_) m = Mod::ToMeasurement(r, std::get<typename Mod::Options>(sensors_.modules), *frame_);
  if (!m) {
    ++module_unused_[i];
    return;
  }
  Dispatch(&Estimator::Add, Measurement(std::move(*m)));
}

inline void EstimatorPipeline::Add(const LogRecord& r) {
  std::visit(
      [this](const auto& m) {
        using R = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<R, ImuSample>) {
          AddImu(m);
        } else if constexpr (std::is_same_v<R, WheelRecord>) {
          AddWheel(m);
        } else if constexpr (std::is_same_v<R, GnssRecord>) {
          AddGnss(m);
        } else if constexpr (std::is_same_v<R, GnssVelocityRecord>) {
          AddGnssVelocity(m);
        } else {
          static_assert(MeasurementModules::kHasRecord<R>, "a record type without its Add");
          AddModuleRecord(m);
        }
      },
      r.data);
}

}  // namespace gins
