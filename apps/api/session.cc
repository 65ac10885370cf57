// api::Session (gins/gins.h): checks each pushed measurement as the log reader checks a line, sorts it in
// through the reorder buffer, and feeds the internal session (solver/estimator_pipeline.h) that owns the estimators;
// their states come back through Emit, converted to the public State.
#include <atomic>
#include <cmath>
#include <deque>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "apps/api/access.h"
#include "apps/api/convert.h"
#include "apps/api/reorder_buffer.h"
#include "core/io/sample_clock.h"
#include "gins/gins.h"
#include "solver/eskf.h"
#include "solver/smoother.h"
#include "solver/summary_keys.h"

namespace gins::api {

class Session::Impl {
 public:
  Impl(const Options& options, const SessionOptions& session_options);
  // The estimators' threads stop before the members their callbacks use (Emit) go.
  ~Impl() { session_.CancelThreads(); }
  Impl(const Impl&) = delete;  // the estimators' callbacks hold `this`
  Impl& operator=(const Impl&) = delete;

  bool Push(LogRecord record);
  void Finish();
  void OnState(StateCallback callback) { callback_ = std::move(callback); }
  bool Poll(State* state);
  bool init_timed_out() const { return !session_.initialized() && session_.elapsed() > options_.init.max_wait; }
  Status GetStatus() const;
  nlohmann::json Stats() const;
  const ::gins::EstimatorPipeline& session() const { return session_; }

 private:
  void Dispatch(const LogRecord& r);
  void Emit(Stream stream, const StateEstimate& e);
  bool Reject(const LogRecord& record, const std::string& reason);
  void RethrowCallbackError();

  const Options options_;
  const SessionOptions session_options_;
  ::gins::EstimatorPipeline session_;
  ReorderBuffer reorder_;
  // The IMU's and the wheels' stamps, regularised in arrival order (input.regularize_stamps).
  SampleClock imu_clock_, wheel_clock_;
  const ImuRange imu_range_;  // a pushed IMU record beyond it is damage, as in a log
  StateCallback callback_;
  std::deque<State> queue_;
  std::exception_ptr callback_error_;  // the first exception of the current call, rethrown at its end
  // Set with callback_error_: Push checks it per record without taking the lock.
  std::atomic<bool> has_callback_error_{false};
  bool finished_ = false;
  InputIssue issue_;                                                  // reused: a valid record allocates nothing
  std::map<std::pair<std::string, std::string>, uint64_t> rejected_;  // (measurement, reason) -> count
  uint64_t accepted_ = 0, rejected_total_ = 0, states_ = 0, states_dropped_ = 0, callback_errors_ = 0;
  // Emit may come from the estimators' threads (SessionOptions::parallel): it, the queue and the counters
  // it keeps are under this lock.
  mutable std::mutex emit_mutex_;
};

Session::Impl::Impl(const Options& options, const SessionOptions& session_options)
    : options_(options),
      session_options_(session_options),
      session_(options_.sensors, options_.init, options_.standstill),
      // GNSS records taken back by gnss.time_offset_s must still find their place among the IMU's.
      reorder_(options_.input.reorder_window + std::abs(options_.sensors.gnss.time_offset)),
      imu_clock_(options_.sensors.imu.max_gap),
      wheel_clock_(options_.sensors.imu.max_gap + options_.sensors.wheel.interval),
      imu_range_(ReaderOptions(options_).imu_range) {
  session_.SetParallel(session_options_.parallel);
  if (!options_.sensors.gnss.raw.obs_file.empty() || !options_.sensors.gnss.raw.nav_file.empty()) {
    if (options_.sensors.gnss.raw.obs_file.empty() || options_.sensors.gnss.raw.nav_file.empty()) {
      throw Error(Error::Kind::kConfig, "raw_gnss: obs_file and nav_file go together (gins run --obs OBS --nav NAV)");
    }
    try {
      session_.SetRawGnssFeed(std::make_unique<RawGnssFeed>(options_.sensors.gnss.raw, options_.input));
    } catch (const InputError& e) {
      throw Error(Error::Kind::kInput, e.what());
    }
  }
  const Mode mode = session_options_.mode;
  const bool all = mode == Mode::kAll;
  if (mode == Mode::kEskf || mode == Mode::kBoth || all) {
    ::gins::StateCallback rts;
    if (all) rts = [this](const StateEstimate& e) { Emit(Stream::kEskfRts, e); };
    session_.AddEstimator(std::make_unique<Eskf>(
        options_.sensors, options_.eskf, options_.standstill, options_.watchdog,
        [this](const StateEstimate& e) { Emit(Stream::kEskf, e); }, std::move(rts)));
  }
  if (mode == Mode::kSmoother || mode == Mode::kBoth || mode == Mode::kBatch || all) {
    // Batch alone: the window runs as the batch's forward pass, its own streams not delivered.
    const bool window = mode != Mode::kBatch;
    ::gins::StateCallback batch;
    if (mode == Mode::kBatch || all) batch = [this](const StateEstimate& e) { Emit(Stream::kBatch, e); };
    session_.AddEstimator(std::make_unique<Smoother>(
        options_.sensors, options_.eskf, options_.smoother, options_.batch, options_.standstill, options_.watchdog,
        window ? ::gins::StateCallback([this](const StateEstimate& e) { Emit(Stream::kSmoother, e); }) : nullptr,
        window ? ::gins::StateCallback([this](const StateEstimate& e) { Emit(Stream::kSmootherOnline, e); }) : nullptr,
        std::move(batch)));
  }
}

bool Session::Impl::Push(LogRecord record) {
  if (finished_) throw Error(Error::Kind::kUsage, "gins::api::Session: Push after Finish");
  if (CheckLogRecord(&record, &issue_, imu_range_) == LineParse::kDamaged) return Reject(record, issue_.reason);
  // At the IMU time of their measurement (gnss.time_offset_s).
  if (GnssRecord* fix = record.get_if<GnssRecord>()) fix->t -= options_.sensors.gnss.time_offset;
  if (GnssVelocityRecord* velocity = record.get_if<GnssVelocityRecord>()) velocity->t -= options_.sensors.gnss.time_offset;
  if (options_.input.regularize_stamps) {
    if (ImuSample* imu = record.get_if<ImuSample>()) imu->t = imu_clock_.Stamp(imu->t);
    if (WheelRecord* wheel = record.get_if<WheelRecord>()) wheel->t = wheel_clock_.Stamp(wheel->t);
  }
  try {
    if (!reorder_.Add(record, [this](const LogRecord& r) { Dispatch(r); })) return Reject(record, "late");
  } catch (const RunError& e) {
    throw Error(Error::Kind::kInput, e.what());  // the data cannot be used as they are (core/imu_checks.h)
  } catch (const InputError& e) {
    throw Error(Error::Kind::kInput, e.what());  // the raw GNSS files (raw_gnss), read as the log goes
  }
  ++accepted_;
  RethrowCallbackError();
  return true;
}

void Session::Impl::Dispatch(const LogRecord& r) { session_.Add(r); }

void Session::Impl::Finish() {
  if (finished_) throw Error(Error::Kind::kUsage, "gins::api::Session: Finish called twice");
  finished_ = true;
  reorder_.Flush([this](const LogRecord& r) { Dispatch(r); });
  try {
    session_.Finish();
  } catch (const RunError& e) {
    throw Error(Error::Kind::kNoSolution, e.what());
  } catch (const InputError& e) {
    throw Error(Error::Kind::kInput, e.what());
  }
  RethrowCallbackError();
}

// Called by the estimators in the middle of their step: nothing may escape into them.
void Session::Impl::Emit(Stream stream, const StateEstimate& e) {
  State s;
  ToState(stream, e, &s);
  if (session_options_.geodetic) {
    const GeodeticPoint g = session_.frame()->ToGeodetic(e.x.p_wb);
    s.lla[0] = g.lat_deg, s.lla[1] = g.lon_deg, s.lla[2] = g.alt_m;
  } else {
    s.lla[0] = s.lla[1] = s.lla[2] = std::numeric_limits<double>::quiet_NaN();
  }
  const std::lock_guard<std::mutex> lock(emit_mutex_);
  ++states_;
  if (!callback_) {
    queue_.push_back(s);
    if (queue_.size() > session_options_.max_queued_states) {
      queue_.pop_front();
      ++states_dropped_;
    }
    return;
  }
  try {
    callback_(s);
  } catch (...) {
    ++callback_errors_;
    if (!callback_error_) callback_error_ = std::current_exception();
    has_callback_error_.store(true, std::memory_order_release);
  }
}

void Session::Impl::RethrowCallbackError() {
  if (!has_callback_error_.load(std::memory_order_acquire)) return;
  const std::lock_guard<std::mutex> lock(emit_mutex_);
  has_callback_error_.store(false, std::memory_order_relaxed);
  if (callback_error_) std::rethrow_exception(std::exchange(callback_error_, nullptr));
}

bool Session::Impl::Reject(const LogRecord& record, const std::string& reason) {
  ++rejected_[{record.info().name, reason}];
  ++rejected_total_;
  return false;
}

bool Session::Impl::Poll(State* state) {
  const std::lock_guard<std::mutex> lock(emit_mutex_);
  if (queue_.empty()) return false;
  *state = queue_.front();
  queue_.pop_front();
  return true;
}

Status Session::Impl::GetStatus() const {
  Status s;
  s.initialized = session_.initialized();
  s.diagnosis = session_.Diagnosis();
  s.init_timed_out = init_timed_out();
  if (session_.frame()) {
    const GeodeticPoint& o = session_.frame()->origin();
    s.origin = Geodetic{o.lat_deg, o.lon_deg, o.alt_m};
  }
  if (session_.first_time() >= 0.0) {
    s.first_time = session_.first_time();
    s.last_time = session_.last_time();
  }
  s.accepted = accepted_;
  s.reordered = reorder_.reordered();
  s.rejected = rejected_total_;
  {
    const std::lock_guard<std::mutex> lock(emit_mutex_);
    s.states = states_;
    s.states_dropped = states_dropped_;
    s.callback_errors = callback_errors_;
  }
  for (const auto& [key, count] : rejected_) s.rejections.push_back({"input", key.first, key.second, count});
  // Each estimator's counts (MeasurementCounts::ToJson: {"used", "rejected": {reason: n}, ...}).
  const nlohmann::json stats = session_.Stats();
  const nlohmann::json estimators = stats.value("estimators", nlohmann::json::object());
  for (const auto& [name, est] : estimators.items()) {
    for (const auto& [measurement, counts] : est.items()) {
      if (!counts.is_object() || !counts.contains("rejected") || !counts["rejected"].is_object()) continue;
      for (const auto& [reason, n] : counts["rejected"].items()) {
        s.rejections.push_back({name, measurement, reason, n.get<uint64_t>()});
      }
    }
    if (est.contains(summary_keys::kWatchdog)) {
      s.watchdog_resets += est[summary_keys::kWatchdog].at(summary_keys::kWatchdogCount).get<uint64_t>();
    }
  }
  return s;
}

nlohmann::json Session::Impl::Stats() const {
  nlohmann::json j = session_.Stats();
  const std::lock_guard<std::mutex> lock(emit_mutex_);
  nlohmann::json rejected = nlohmann::json::object();
  for (const auto& [key, count] : rejected_) rejected[key.first][key.second] = count;
  j[summary_keys::kSession] = {{"accepted", accepted_},
                  {summary_keys::kReorderWindow, reorder_.window()},
                  {"reordered", reorder_.reordered()},
                  {summary_keys::kStamps,
                   {{"imu_regularized", imu_clock_.regularized()},
                    {"imu_max_correction_s", imu_clock_.max_correction()},
                    {"odom_regularized", wheel_clock_.regularized()},
                    {"odom_max_correction_s", wheel_clock_.max_correction()}}},
                  {"rejected", rejected},
                  {"states", states_},
                  {"states_dropped", states_dropped_},
                  {"callback_errors", callback_errors_}};
  return j;
}

// --- Session ------------------------------------------------------------------------------------------------

Session::Session(const Config& config, const SessionOptions& options)
    : impl_(std::make_unique<Impl>(internal::Access::options(config), options)) {}

Session::Session(const Config& config, Mode mode) : Session(config, SessionOptions{mode}) {}

Session::~Session() = default;
Session::Session(Session&&) noexcept = default;
Session& Session::operator=(Session&&) noexcept = default;

void Session::OnState(StateCallback callback) { impl_->OnState(std::move(callback)); }
bool Session::Push(const Imu& imu) { return impl_->Push(ToLogRecord(imu)); }
bool Session::Push(const Wheel& wheel) { return impl_->Push(ToLogRecord(wheel)); }
bool Session::Push(const Gnss& fix) { return impl_->Push(ToLogRecord(fix)); }
bool Session::Push(const GnssVelocity& velocity) { return impl_->Push(ToLogRecord(velocity)); }
bool Session::Push(const Record& record) { return impl_->Push(ToLogRecord(record)); }
void Session::Finish() { impl_->Finish(); }
bool Session::Poll(State* state) { return impl_->Poll(state); }
bool Session::initialized() const { return impl_->session().initialized(); }
bool Session::init_timed_out() const { return impl_->init_timed_out(); }
Status Session::status() const { return impl_->GetStatus(); }
std::string Session::StatsJson() const { return impl_->Stats().dump(); }

const ::gins::EstimatorPipeline& internal::Access::session(const Session& session) { return session.impl_->session(); }
nlohmann::json internal::Access::stats(const Session& session) { return session.impl_->Stats(); }

}  // namespace gins::api
