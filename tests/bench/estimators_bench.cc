// Estimator costs on a seeded simulated drive: ESKF prediction per IMU sample and each update; one
// smoother step (keyframe, solve, marginalisation) at the default window.
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <variant>
#include <vector>

#include "core/sim/simulator.h"
#include "estimators_from_options.h"
#include "solver/eskf.h"
#include "solver/estimator_pipeline.h"
#include "solver/smoother.h"
#include "sim_feed.h"
#include "test_scenarios.h"

namespace gins {
namespace {

// The drive's records, generated once.
const std::vector<SimRecord>& DriveRecords() {
  static const std::vector<SimRecord> records = [] {
    std::vector<SimRecord> out;
    Simulator sim(test::TestDrive(1));
    SimRecord r;
    while (sim.Next(&r)) out.push_back(r);
    return out;
  }();
  return records;
}

// Runs the whole drive through one estimator per iteration; reports the cost per IMU sample and per
// GNSS epoch (the smoother solves once per epoch).
template <typename MakeEstimator>
void RunDrive(benchmark::State& state, MakeEstimator make) {
  const auto& records = DriveRecords();
  const Options options = test::TestRunOptions(test::TestDrive(1));
  int64_t imu = 0, gnss = 0;
  for (auto _ : state) {
    EstimatorPipeline session(options.sensors, options.init, options.standstill);
    session.AddEstimator(make(options));
    for (const auto& r : records) {
      test::FeedSession(&session, r);
      imu += r.is<ImuSample>();
      gnss += r.is<GnssRecord>();
    }
    session.Finish();
  }
  state.counters["per_imu_sample_us"] = benchmark::Counter(
      static_cast<double>(imu) * 1e-6, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["per_gnss_epoch_ms"] = benchmark::Counter(
      static_cast<double>(gnss) * 1e-3, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_EskfDrive(benchmark::State& state) {
  RunDrive(state, [](const Options& o) { return test::MakeEskf(o, nullptr); });
}
BENCHMARK(BM_EskfDrive)->Unit(benchmark::kMillisecond);

void BM_SmootherDrive(benchmark::State& state) {
  RunDrive(state, [](const Options& o) { return test::MakeSmoother(o, nullptr, nullptr); });
}
BENCHMARK(BM_SmootherDrive)->Unit(benchmark::kMillisecond);

// ESKF steps in isolation, from a state initialised on the drive.
class EskfFixture {
 public:
  explicit EskfFixture(const Options& options = test::TestRunOptions(test::TestDrive(1))) : options_(options) {
    auto eskf = test::MakeEskf(options_, nullptr);
    eskf_ = eskf.get();
    session_ = std::make_unique<EstimatorPipeline>(options_.sensors, options_.init, options_.standstill);
    session_->AddEstimator(std::move(eskf));
    for (const auto& r : DriveRecords()) {
      test::FeedSession(session_.get(), r);
      if (session_->initialized() && r.is<GnssRecord>()) break;
    }
  }
  Eskf* eskf() { return eskf_; }

 private:
  Options options_;
  std::unique_ptr<EstimatorPipeline> session_;
  Eskf* eskf_ = nullptr;
};

void BM_EskfPredict(benchmark::State& state) {
  EskfFixture f;
  ImuSample s;
  s.t = f.eskf()->state().t;
  s.acc = Vec3(0.1, 0.0, 9.8);
  for (auto _ : state) {
    s.t += 0.01;
    f.eskf()->AddImu(s);
  }
}
BENCHMARK(BM_EskfPredict);

void BM_EskfGnssUpdate(benchmark::State& state) {
  EskfFixture f;
  GnssMeasurement m;
  m.heading_valid = state.range(0) != 0;
  m.sigma_yaw = 0.01;
  m.sigma_w = Vec3(0.02, 0.02, 0.03);
  for (auto _ : state) {
    const NavState& x = f.eskf()->state();
    m.t = x.t;
    m.p_w = x.p_wb + x.q_wb * Vec3(-0.17, -0.2, 0.0);
    m.yaw_G = 0.0;
    f.eskf()->Add(m);
  }
}
BENCHMARK(BM_EskfGnssUpdate)->Arg(0)->Arg(1)->ArgName("heading");

// Fails the benchmark unless every update it ran was accepted (a gated-out update skips the covariance
// update and would time the wrong thing).
void CheckAllUsed(benchmark::State& state, const nlohmann::json& counts, uint64_t expected) {
  if (counts["used"].get<uint64_t>() != expected) {
    state.SkipWithError(("updates not all used: " + counts.dump()).c_str());
  }
}

// Wheel-speed update. The non-holonomic update runs at its own rate (vehicle.nhc_rate_hz) as time advances,
// not with the wheel record: this benchmark, whose time stands, times the wheel update alone.
void BM_EskfWheelUpdate(benchmark::State& state) {
  EskfFixture f;
  const uint64_t used0 = f.eskf()->Stats()["wheel"]["used"].get<uint64_t>();
  WheelMeasurement w;
  w.sigma = 0.1;
  w.interval = 0.1;
  for (auto _ : state) {
    w.t = f.eskf()->state().t;
    w.speed = 0.0;
    f.eskf()->Add(w);
  }
  CheckAllUsed(state, f.eskf()->Stats()["wheel"], used0 + state.iterations());
}
BENCHMARK(BM_EskfWheelUpdate);

// Standstill update: zero velocity and zero rate (the mean gyro reading since the last
// update observes the gyro bias). Each iteration first feeds, untimed, 0.1 s of quiet IMU samples (the
// session sends a standstill every 0.1 s); only the update is timed (manual time).
void BM_EskfStandstillUpdate(benchmark::State& state) {
  EskfFixture f;
  Eskf* eskf = f.eskf();
  const uint64_t used0 = eskf->Stats()["zero_velocity"]["used"].get<uint64_t>();
  ImuSample s;
  s.t = eskf->state().t;
  StandstillMeasurement m;
  m.since = s.t - 10.0;  // standing since the start of the drive
  for (auto _ : state) {
    for (int k = 0; k < 10; ++k) {
      const NavState& x = eskf->state();
      s.t += 0.01;
      s.gyro = x.bg;
      s.acc = x.ba - x.q_wb.conjugate() * eskf->gravity();
      eskf->AddImu(s);
    }
    m.t = s.t;
    const auto t0 = std::chrono::steady_clock::now();
    eskf->Add(m);
    const auto t1 = std::chrono::steady_clock::now();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
  }
  // Two updates per iteration: zero velocity and zero rate.
  CheckAllUsed(state, eskf->Stats()["zero_velocity"], used0 + 2 * state.iterations());
}
BENCHMARK(BM_EskfStandstillUpdate)->UseManualTime();

// ---------------------------------------------------------------------------------------------------------
// One smoother step at the default window.

// What a session passes to its estimators after initialisation, recorded once so that the step benchmark
// feeds the smoother alone.
using EstimatorInput = std::variant<ImuSample, Measurement>;

// The GNSS fix an input holds, or null.
const GnssMeasurement* FixOf(const EstimatorInput& in) {
  const Measurement* m = std::get_if<Measurement>(&in);
  return m != nullptr ? std::get_if<GnssMeasurement>(m) : nullptr;
}

class Recorder : public Estimator {
 public:
  Recorder(InitResult* init, std::vector<EstimatorInput>* inputs) : init_(init), inputs_(inputs) {}
  std::string name() const override { return "recorder"; }
  void Initialize(const InitResult& init) override { *init_ = init; }
  void AddImu(const ImuSample& imu) override { inputs_->emplace_back(imu); }
  void Add(const Measurement& m) override { inputs_->emplace_back(m); }
  void AddRestState(const StateEstimate&) override {}
  void Finish() override {}
  nlohmann::json Stats() const override { return {}; }

 private:
  InitResult* init_;
  std::vector<EstimatorInput>* inputs_;
};

struct FeedEstimator {
  Estimator* e;
  void operator()(const ImuSample& m) const { e->AddImu(m); }
  void operator()(const Measurement& m) const { e->Add(m); }
};

// TestDrive's sensors without outages and with heading on every fix; after the 20 s standstill and the
// start, about 10 min of driving without stops (turns, hills, speed changes).
SimOptions StepDrive() {
  SimOptions s = test::TestDrive(1);
  s.gnss_outages.clear();
  s.heading_invalid_fraction = 0.0;
  const double d = kDegToRad;
  s.segments = {{20.0, 0.0, 0.0, 0.0}, {10.0, 1.0, 0.0, 0.0}};  // standstill (initialisation), to 10 m/s
  const SimSegment cycle[] = {
      {15.0, 0.0, 6.0 * d, 0.0},    // left turn, 90°
      {15.0, 0.3, 0.0, 3.0 * d},    // uphill, speeding up
      {10.0, 0.0, 0.0, 0.0},        // crest
      {15.0, -0.2, 0.0, -3.0 * d},  // downhill
      {10.0, 0.0, -9.0 * d, 0.0},   // right turn, 90°
      {10.0, -0.15, 0.0, 0.0},      // back to 10 m/s
      {30.0, 0.0, 0.0, 0.0},        // cruise
      {20.0, 0.0, 4.5 * d, 0.0},    // gentle left
      {20.0, 0.0, -4.5 * d, 0.0},   // gentle right
  };
  for (int k = 0; k < 4; ++k) s.segments.insert(s.segments.end(), std::begin(cycle), std::end(cycle));
  return s;
}

struct StepDriveInputs {
  Options options;
  double start_time = 0.0;  // of the drive
  InitResult init;
  std::vector<EstimatorInput> inputs;  // after initialisation, in order
};

const StepDriveInputs& StepInputs() {
  static const StepDriveInputs in = [] {
    StepDriveInputs out;
    const SimOptions sim = StepDrive();
    out.options = test::TestRunOptions(sim);
    out.start_time = sim.start_time;
    EstimatorPipeline session(out.options.sensors, out.options.init, out.options.standstill);
    session.AddEstimator(std::make_unique<Recorder>(&out.init, &out.inputs));
    Simulator simulator(sim);
    SimRecord r;
    while (simulator.Next(&r)) test::FeedSession(&session, r);
    return out;
  }();
  return in;
}

// A smoother initialised on StepDrive and fed until it has driven 10 s at speed (window full of moving
// keyframes); then each
// Step() feeds the inputs up to and including the next GNSS fix (1 s: 100 IMU samples, 10 wheel speeds,
// one fix with heading): one keyframe, one solve, one marginalisation.
class SmootherFixture {
 public:
  SmootherFixture() : SmootherFixture(StepInputs().options) {}
  explicit SmootherFixture(const Options& o)
      : smoother_(o.sensors, o.eskf, o.smoother, o.batch, o.standstill, o.watchdog, nullptr, nullptr) {
    const StepDriveInputs& in = StepInputs();
    smoother_.Initialize(in.init);
    const double t_start = in.start_time + 40.0;  // 20 s standstill, 10 s to 10 m/s, 10 s of driving
    while (next_ < in.inputs.size()) {
      const EstimatorInput& m = in.inputs[next_++];
      std::visit(FeedEstimator{&smoother_}, m);
      if (const GnssMeasurement* fix = FixOf(m); fix != nullptr && fix->t >= t_start) break;
    }
    stats0_ = smoother_.Stats();
  }
  // False (nothing fed) when the drive has no further fix.
  bool Step() {
    const auto& inputs = StepInputs().inputs;
    size_t end = next_;
    while (end < inputs.size() && FixOf(inputs[end]) == nullptr) ++end;
    if (end == inputs.size()) return false;
    for (; next_ <= end; ++next_) std::visit(FeedEstimator{&smoother_}, inputs[next_]);
    return true;
  }
  // Smoother statistic accumulated since the fixture's warm-up.
  double Delta(const char* key) const { return smoother_.Stats()[key].get<double>() - stats0_[key].get<double>(); }

 private:
  Smoother smoother_;
  size_t next_ = 0;
  nlohmann::json stats0_;
};

// One smoother step at the default window (smoother.window_size keyframes): IMU preintegration over 1 s,
// wheel factor, the keyframe at the GNSS fix with its GNSS and heading factors, the Ceres solve with the
// residual checks, and the marginalisation of the oldest keyframe (with its covariance and output). Setup
// (and re-creating the smoother when the drive runs out) is excluded. Counters: per step, keyframes,
// solves, marginalisations, Ceres iterations, and the smoother's own timing of solve and MarginalizeOldest.
void BM_SmootherStep(benchmark::State& state) {
  StepInputs();
  auto f = std::make_unique<SmootherFixture>();
  const char* keys[] = {"keyframes", "solves", "marginalizations", "iterations", "solve_time_s",
                        "marginalization_time_s"};
  double totals[6] = {};
  auto accumulate = [&] {
    for (int k = 0; k < 6; ++k) totals[k] += f->Delta(keys[k]);
  };
  for (auto _ : state) {
    if (!f->Step()) {
      state.PauseTiming();
      accumulate();
      f = std::make_unique<SmootherFixture>();
      state.ResumeTiming();
      f->Step();
    }
  }
  accumulate();
  const double n = static_cast<double>(state.iterations());
  state.counters["keyframes"] = totals[0] / n;
  state.counters["solves"] = totals[1] / n;
  state.counters["marginalizations"] = totals[2] / n;
  state.counters["ceres_iterations"] = totals[3] / n;
  state.counters["solve_ms"] = 1e3 * totals[4] / n;
  state.counters["marginalize_oldest_ms"] = 1e3 * totals[5] / n;
}
BENCHMARK(BM_SmootherStep)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gins
