#include "solver/estimator_pipeline.h"

#include <glog/logging.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>

#include "core/gnss_noise.h"
#include "core/wheel_model.h"

namespace gins {
namespace {
// Records kept while waiting for the first GNSS fix (a few minutes of 250 Hz IMU).
constexpr size_t kMaxPending = 100000;
}  // namespace

EstimatorPipeline::EstimatorPipeline(const SensorOptions& sensors, const InitOptions& init,
                                     const StandstillOptions& standstill)
    : sensors_(sensors), init_options_(init), standstill_options_(standstill) {
  if (sensors_.gnss.origin) frame_.emplace(*sensors_.gnss.origin);
}

void EstimatorPipeline::AddEstimator(std::unique_ptr<Estimator> estimator) {
  estimators_.push_back({std::move(estimator), {}});
}

// One estimator's thread: batches of tasks in order, a bounded queue (the reader waits rather than buffer
// the log), the first exception kept for the caller.
struct EstimatorPipeline::Worker {
  static constexpr size_t kBatch = 256;     // tasks handed over at once
  static constexpr size_t kMaxQueued = 64;  // batches waiting before the caller waits

  explicit Worker(Timed* te) : target(te), thread([this] { Run(); }) {}
  void Submit(bool force) {
    if (pending.empty() || (!force && pending.size() < kBatch)) return;
    std::unique_lock<std::mutex> lock(mutex);
    space.wait(lock, [&] { return queue.size() < kMaxQueued; });
    queue.push_back(std::move(pending));
    pending.clear();
    pending.reserve(kBatch);
    ready.notify_one();
  }
  // Runs what was handed over and ends the thread; cancel: drops it instead (the session is being
  // destroyed without Finish, after an error: the callbacks' owners may be gone).
  void Stop(bool cancel = false) {
    if (!cancel) Submit(true);
    {
      std::lock_guard<std::mutex> lock(mutex);
      done = true;
      if (cancel) {
        queue.clear();
        cancelled = true;
      }
    }
    ready.notify_one();
    if (thread.joinable()) thread.join();
  }
  void Run() {
    for (;;) {
      std::vector<std::function<void(Estimator&)>> batch;
      {
        std::unique_lock<std::mutex> lock(mutex);
        ready.wait(lock, [&] { return !queue.empty() || done; });
        if (queue.empty()) return;
        batch = std::move(queue.front());
        queue.pop_front();
      }
      space.notify_one();
      const auto t0 = std::chrono::steady_clock::now();
      for (auto& task : batch) {
        if (error || cancelled) break;  // failed (the caller rethrows at Finish) or cancelled
        try {
          task(*target->estimator);
        } catch (...) {
          error = std::current_exception();
        }
      }
      target->time += std::chrono::steady_clock::now() - t0;
    }
  }

  Timed* target;
  std::vector<std::function<void(Estimator&)>> pending;
  std::mutex mutex;
  std::condition_variable ready, space;
  std::deque<std::vector<std::function<void(Estimator&)>>> queue;
  bool done = false;
  std::atomic<bool> cancelled{false};
  std::exception_ptr error;  // written by the thread, read after Stop
  std::thread thread;        // last: starts once the members above exist
};

EstimatorPipeline::~EstimatorPipeline() { CancelThreads(); }

void EstimatorPipeline::CancelThreads() {
  for (auto& w : workers_) w->Stop(true);
  workers_.clear();
}

template <typename M>
void EstimatorPipeline::Dispatch(void (Estimator::*add)(const M&), const M& m) {
  if (parallel_ && estimators_.size() > 1) {
    DispatchTask([add, m](Estimator& e) { (e.*add)(m); });
    return;
  }
  // In this thread: no task object (a heap allocation per record at IMU rate).
  for (Timed& te : estimators_) te.Call([&](Estimator& e) { (e.*add)(m); });
}

void EstimatorPipeline::DispatchTask(const std::function<void(Estimator&)>& task) {
  if (parallel_ && workers_.empty() && estimators_.size() > 1) {
    // estimators_ no longer grows (the first record came): its elements keep their addresses.
    for (size_t i = 1; i < estimators_.size(); ++i) workers_.push_back(std::make_unique<Worker>(&estimators_[i]));
  }
  for (size_t i = 0; i < estimators_.size(); ++i) {
    if (i > 0 && !workers_.empty()) {
      Worker& w = *workers_[i - 1];
      w.pending.push_back(task);
      w.Submit(false);
      continue;
    }
    estimators_[i].Call(task);
  }
}

void EstimatorPipeline::StopWorkers() {
  std::exception_ptr error;
  for (auto& w : workers_) {
    w->Stop();
    if (!error) error = w->error;
  }
  workers_.clear();
  if (error) std::rethrow_exception(error);
}

void EstimatorPipeline::Touch(double t) {
  if (first_t_ < 0.0) first_t_ = t;
  last_t_ = std::max(last_t_, t);
}

void EstimatorPipeline::EnsureInitializer() {
  if (init_ || !frame_) return;
  earth_ = EarthModel::FromOptions(*frame_, sensors_.gravity);
  g_norm_ = earth_.g_norm();
  InitOptions init = init_options_;
  if (raw_feed_ || raw_.epochs > 0) {
    // Raw GNSS: the Dopplers and carrier phases pin the yaw within seconds of the start, while single-point
    // fixes would hold a 1° acceptance for a minute (docs/estimators.md, "Tightly coupled GNSS").
    init.max_attitude_sigma = std::max(init.max_attitude_sigma, sensors_.gnss.raw.init_max_attitude_sigma);
  }
  init_ = std::make_unique<Initializer>(sensors_, init, standstill_options_, earth_);
  standstill_ = std::make_unique<StandstillDetector>(standstill_options_, g_norm_, sensors_.wheel.interval);
  // Replay what arrived before the world frame existed, in time order.
  size_t i = 0, j = 0;
  while (i < pending_imu_.size() || j < pending_wheel_.size()) {
    if (j >= pending_wheel_.size() || (i < pending_imu_.size() && pending_imu_[i].t <= pending_wheel_[j].t)) {
      init_->AddImu(pending_imu_[i++]);
    } else {
      init_->AddWheel(pending_wheel_[j++]);
    }
  }
  pending_imu_ = {};
  pending_wheel_ = {};
}

void EstimatorPipeline::WatchImuInterval(double t) {
  constexpr int kRunForRateChange = 10;
  const std::optional<double> last = last_imu_t_;
  last_imu_t_ = t;
  if (!last) return;
  const double dt = t - *last;
  if (!(dt > 0.0)) {
    ++imu_same_stamp_;
    return;
  }
  if (dt > sensors_.imu.max_gap) return;  // a gap: the estimators count it
  const auto near = [](double a, double b) { return std::abs(a - b) <= 0.1 * b; };
  if (imu_nominal_dt_ <= 0.0 || near(dt, imu_nominal_dt_)) {
    if (imu_nominal_dt_ <= 0.0) imu_nominal_dt_ = dt;
    imu_candidate_runs_ = 0;
    return;
  }
  ++imu_jitter_;
  if (imu_candidate_runs_ > 0 && near(dt, imu_candidate_dt_)) {
    if (++imu_candidate_runs_ >= kRunForRateChange) {
      ++imu_rate_changes_;
      imu_jitter_ -= static_cast<uint64_t>(imu_candidate_runs_);  // the new rate's samples, not jitter
      imu_nominal_dt_ = imu_candidate_dt_;
      imu_candidate_runs_ = 0;
    }
  } else {
    imu_candidate_dt_ = dt;
    imu_candidate_runs_ = 1;
  }
}

void EstimatorPipeline::AddImu(const ImuSample& raw) {
  DrainRawGnss(raw.t);
  Touch(raw.t);
  WatchImuInterval(raw.t);
  ImuSample s = raw;
  s.gyro = sensors_.imu.R_b_imu * raw.gyro;
  s.acc = sensors_.imu.R_b_imu * raw.acc;
  imu_check_.Add(s.acc);
  switch (imu_check_.Judge(sensors_.vehicle.nonholonomic)) {
    case ImuAxesAndUnitsCheck::Outcome::kRefuse:
      throw RunError(imu_check_.message());
    case ImuAxesAndUnitsCheck::Outcome::kWarn:
      if (imu_warning_.empty()) {
        imu_warning_ = imu_check_.message();
        LOG(WARNING) << imu_warning_;
      }
      break;
    default:
      break;
  }
  if (sensors_.vehicle.nonholonomic) {
    turn_check_.AddImu(s.t, s.gyro, s.acc);
    clock_check_.AddImu(s.t, s.acc);
  }
  EnsureInitializer();
  if (!init_) {
    if (pending_imu_.size() < kMaxPending) {
      pending_imu_.push_back(s);
    } else {
      ++pending_dropped_;
    }
  } else if (!initialized_) {
    init_->AddImu(s);
    SendRestStates();
  } else {
    Dispatch(&Estimator::AddImu, s);
  }
  if (standstill_) {
    standstill_->AddImu(s);
    if (initialized_) DetectStandstill(s.t);
  }
}

namespace {
StateEstimate RestEstimate(const RestState& r) {
  StateEstimate e;
  e.x = r.x;
  e.sigma_p = r.sigma_p;
  e.sigma_v = r.sigma_v;
  e.sigma_att = r.sigma_att;
  return e;
}
}  // namespace

void EstimatorPipeline::SendRestStates() {
  rest_scratch_.clear();
  init_->RestStates(last_rest_t_, &rest_scratch_);
  for (const RestState& r : rest_scratch_) {
    if (rest_held_) {
      Dispatch(&Estimator::AddRestState, RestEstimate(*rest_held_));
      ++rest_sent_;
    }
    rest_held_ = r;
    last_rest_t_ = r.x.t;
  }
}

void EstimatorPipeline::FlushRestState(double init_t) {
  if (rest_held_ && rest_held_->x.t < init_t) {
    Dispatch(&Estimator::AddRestState, RestEstimate(*rest_held_));
    ++rest_sent_;
  }
  rest_held_.reset();
}

void EstimatorPipeline::DetectStandstill(double t) {
  constexpr double kInterval = 0.1;  // s between standstill updates
  if (!standstill_->Standing()) {
    standing_since_ = -1.0;
    return;
  }
  // The detector looked back over its window: the vehicle has stood at least that long.
  if (standing_since_ < 0.0) standing_since_ = t - standstill_options_.window;
  if (t - last_standstill_sent_ < kInterval - 1e-9) return;
  last_standstill_sent_ = t;
  ++standstill_sent_;
  StandstillMeasurement m{t, standing_since_};
  if (standstill_->Decide() == StandstillDetector::State::kQuietUnwitnessed) {
    m.witnessed = false;
    m.acc_mean_b = standstill_->WindowMeanAcc();
    m.window_s = standstill_options_.window;
  }
  Dispatch(&Estimator::Add, Measurement(m));
}

void EstimatorPipeline::AddWheel(const WheelRecord& o) {
  DrainRawGnss(o.t);
  Touch(o.t);
  if (!sensors_.wheel.enabled) {
    ++odom_ignored_;
    return;
  }
  const WheelMeasurement w = WheelFromOdom(o);
  EnsureInitializer();
  if (standstill_) standstill_->AddWheel(w);
  if (!init_) {
    if (pending_wheel_.size() < kMaxPending) {
      pending_wheel_.push_back(w);
    } else {
      ++pending_dropped_;
    }
  } else if (!initialized_) {
    init_->AddWheel(w);
  } else {
    Dispatch(&Estimator::Add, Measurement(w));
  }
}

WheelMeasurement EstimatorPipeline::WheelFromOdom(const WheelRecord& o) {
  const WheelOptions& wo = sensors_.wheel;
  // The pulses were counted since the previous record: its spacing is the interval, within half the
  // nominal one either way (clock jitter, counted); a longer spacing means records were lost, and the
  // record's own count then covers the nominal interval only (a gap, counted).
  double interval = wo.interval;
  if (last_wheel_t_) {
    const double spacing = o.t - *last_wheel_t_;
    if (spacing > 0.5 * wo.interval && spacing < 1.5 * wo.interval) {
      interval = spacing;
      if (std::abs(spacing - wo.interval) > 0.1 * wo.interval) ++wheel_jitter_;
    } else if (spacing >= 1.5 * wo.interval) {
      ++wheel_gaps_;
    }
  }
  last_wheel_t_ = o.t;
  WheelMeasurement w;
  w.t = o.t;
  const double left = WheelSpeedFromPulses(o.left_pulses, wo.radius, wo.pulses_per_rev, interval);
  const double right = WheelSpeedFromPulses(o.right_pulses, wo.radius, wo.pulses_per_rev, interval);
  w.speed = 0.5 * (left + right);
  w.sigma = wo.speed_sigma;
  w.interval = interval;
  w.distance = w.speed * interval;
  w.standstill = o.left_pulses == 0.0 && o.right_pulses == 0.0;
  if (wo.track > 0.0) {
    // wheel.speed_sigma_m_s is the mean's σ: each wheel's is √2 larger, their difference's 2×.
    w.has_yaw_rate = true;
    w.yaw_rate = (right - left) / wo.track;
    w.yaw_rate_sigma = 2.0 * wo.speed_sigma / wo.track;
  }
  return w;
}

void EstimatorPipeline::AddGnss(const GnssRecord& g) {
  DrainRawGnss(g.t);
  Touch(g.t);
  if (DropForSimulatedOutage(g.t)) return;
  UseFix(g, nullptr);
}

void EstimatorPipeline::UseFix(const GnssRecord& g, const RawGnssMeasurement* raw) {
  if (!frame_) frame_.emplace(GeodeticPoint{g.lat_deg, g.lon_deg, g.alt_m});
  EnsureInitializer();
  last_fix_geo_ = GeodeticPoint{g.lat_deg, g.lon_deg, g.alt_m};
  GnssMeasurement m;
  m.t = g.t;
  m.p_w = frame_->ToEnu({g.lat_deg, g.lon_deg, g.alt_m});
  // A logged σ is trusted down to a floor: a zero σ would make the fix infinitely certain.
  m.sigma_w = g.has_sigma ? g.sigma_enu.cwiseMax(sensors_.gnss.min_sigma) : sensors_.gnss.sigma_enu;
  // Successive fixes repeat much the same error: each is worth less than an independent one.
  const double since_fix = last_fix_t_ ? g.t - *last_fix_t_ : std::numeric_limits<double>::infinity();
  last_fix_t_ = g.t;
  m.sigma_w *= CorrelatedNoiseInflation(since_fix, sensors_.gnss.error_correlation);
  m.heading_valid = g.heading_valid;
  // The receiver's heading is against true north at the antenna; w's north is the origin's.
  m.yaw_G = g.heading_valid ? LocalYawToWorld(*frame_, *last_fix_geo_, CompassDegToEnuYaw(g.heading_deg))
                            : CompassDegToEnuYaw(g.heading_deg);
  m.sigma_yaw = sensors_.gnss.heading_sigma;
  if (standstill_) standstill_->AddGnss(m);
  if (sensors_.vehicle.nonholonomic) {
    const double sigma_h = m.sigma_w.head<2>().norm() / std::sqrt(2.0);
    turn_check_.AddFix(m.t, m.p_w, sigma_h);
    if (turn_check_.outcome() == TurnRateCheck::Outcome::kRefuse) throw RunError(turn_check_.message());
    clock_check_.AddFix(m.t, m.p_w, sigma_h);
    if (clock_check_.outcome() == ClockOffsetCheck::Outcome::kRefuse) throw RunError(clock_check_.message());
    if (g.heading_valid && sensors_.gnss.use_heading) {
      heading_check_.AddFix(m.t, m.p_w, sigma_h, g.heading_deg, sensors_.gnss.mount_yaw);
      if (heading_check_.outcome() == HeadingCourseCheck::Outcome::kRefuse) throw RunError(heading_check_.message());
    }
  }
  if (!initialized_) {
    init_->AddGnss(m);
    if (init_->done()) {
      initialized_ = true;
      FlushRestState(init_->result().x0.t);
      Dispatch(&Estimator::Initialize, init_->result());
    } else {
      SendRestStates();
    }
  } else if (raw != nullptr) {
    RawGnssMeasurement with_fix = *raw;
    with_fix.has_fix = true;
    with_fix.fix = m;
    Dispatch(&Estimator::Add, Measurement(std::move(with_fix)));
  } else {
    Dispatch(&Estimator::Add, Measurement(m));
  }
}

void EstimatorPipeline::AddGnssVelocity(const GnssVelocityRecord& g) {
  DrainRawGnss(g.t);
  Touch(g.t);
  const bool in_outage = initialized_ && !outage_schedule_.empty() && outage_schedule_.Contains(g.t, first_t_);
  if (!sensors_.gnss.use_velocity || !last_fix_geo_ || !init_ || in_outage) {
    ++gvel_unused_;
    return;
  }
  GnssVelocityMeasurement m;
  m.t = g.t;
  m.v_w = frame_->RotationFromLocalEnu(*last_fix_geo_) * g.v_enu;
  m.sigma_w = g.has_sigma ? g.sigma_enu.cwiseMax(sensors_.gnss.min_velocity_sigma) : sensors_.gnss.velocity_sigma_enu;
  if (standstill_) standstill_->AddGnssVelocity(m);
  if (!initialized_) {
    init_->AddGnssVelocity(m);
    return;
  }
  Dispatch(&Estimator::Add, Measurement(m));
}

// --- Simulated GNSS outages ---------------------------------------------------------------------------------
bool EstimatorPipeline::DropForSimulatedOutage(double t) {
  gnss_gaps_.Add(t);
  if (outage_schedule_.empty() || !outage_schedule_.Contains(t, first_t_)) return false;
  if (!initialized_) {
    ++outage_kept_before_init_;
    return false;
  }
  ++outage_dropped_;
  return true;
}

std::string EstimatorPipeline::Diagnosis() const {
  if (initialized_) return "initialised";
  if (!init_) return "no GNSS fix, so no world frame";
  return init_->Diagnosis();
}

void EstimatorPipeline::Finish() {
  FinishRawGnss();
  if (!initialized_) throw RunError(Diagnosis());
  DispatchTask([](Estimator& e) { e.Finish(); });
  StopWorkers();
}

}  // namespace gins
