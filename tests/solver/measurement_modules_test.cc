// A measurement module through the pipeline and both estimators (core/measurement_module.h: the pipeline's
// AddModuleRecord, the ESKF's UseModule, the smoother's module attacher), with the barometer: on a drive
// whose fixes are poor in height, its records make every estimate's height far better, a burst of wild
// readings is gated away in both estimators, and records before the initialisation are counted, not used.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "drive_harness.h"
#include "test_scenarios.h"

namespace gins {
namespace GINS_TEST_FILE {

using Baro = BarometerModule;

// Fixes good across (0.3 m) and poor in height (3 m), as a single-point receiver's.
SimOptions PoorHeightDrive(unsigned seed) {
  SimOptions sim = test::TestDrive(seed);
  sim.gnss_sigma_enu = Vec3(0.3, 0.3, 3.0);
  return sim;
}

Options PoorHeightOptions(const SimOptions& sim) {
  Options o = test::TestRunOptions(sim);
  o.sensors.gnss.sigma_enu = sim.gnss_sigma_enu;
  return o;
}

// BARO records at 10 Hz (every tenth IMU sample) from the truth's ellipsoidal height, white noise of σ; the
// readings in [wild_from, wild_to) (s after the start) are 40 m off.
test::RecordHook WithBaro(const SimOptions& sim, double sigma, double wild_from = 0.0, double wild_to = 0.0) {
  auto rng = std::make_shared<std::mt19937>(11);
  auto count = std::make_shared<int>(0);
  const LocalEnuFrame w(sim.origin);
  return [=](const SimRecord& rec, const std::function<void(const SimRecord&)>& feed, EstimatorPipeline& session) {
    feed(rec);
    if (!rec.is<ImuSample>() || (*count)++ % 10 != 0) return;
    std::normal_distribution<double> n(0.0, sigma);
    const double t = rec.t();
    const bool wild = t - sim.start_time >= wild_from && t - sim.start_time < wild_to;
    session.Add(LogRecord{Baro::Record{t, w.ToGeodetic(rec.truth.p_wb).alt_m + n(*rng) + (wild ? 40.0 : 0.0), sigma}});
  };
}

// Good readings a gate of probability p rejects: about (1 − p)·n of n (Poisson); at n = 2000 and p = 0.999
// chance passes this bound less than once in 10⁵ runs.
uint64_t FalseRejectionBound(uint64_t offered) {
  return static_cast<uint64_t>(5.0 * (1.0 - BarometerModule::Options{}.gate_probability) * offered) + 3;
}

// One drive without and one with the barometer (a burst of 30 readings 40 m off in it, while driving).
TEST(MeasurementModules, BarometerFixesTheHeightInEveryEstimatorAndAWildBurstIsGated) {
  const SimOptions sim = PoorHeightDrive(8);
  const Options options = PoorHeightOptions(sim);
  const double sigma = 0.3, wild_from = 90.0, wild_to = 93.0;
  const test::DriveRun without = test::RunDriveThroughSession(sim, options, nullptr, true, true, true);
  const test::DriveRun with =
      test::RunDriveThroughSession(sim, options, WithBaro(sim, sigma, wild_from, wild_to), true, true, true);
  ASSERT_TRUE(without.initialized && with.initialized);
  const double from = with.init_t + 10.0;
  const std::pair<const char*, std::vector<StateEstimate> test::DriveRun::*> streams[] = {
      {"eskf", &test::DriveRun::eskf},         {"eskf_rts", &test::DriveRun::eskf_rts},
      {"smoother", &test::DriveRun::smoother}, {"batch", &test::DriveRun::batch}};
  const double t0 = sim.start_time + wild_from;
  for (const auto& [name, stream] : streams) {
    const test::DriveErrors e0 = test::Errors(without, without.*stream, from);
    const test::DriveErrors e1 = test::Errors(with, with.*stream, from);
    const test::DriveErrors burst = test::Errors(with, with.*stream, t0, t0 + 10.0);
    std::printf("[ %-9s] height rmse %.3f m without the barometer, %.3f m with it (%.3f m around the burst)\n",
                name, e0.rmse_v, e1.rmse_v, burst.rmse_v);
    ASSERT_GT(e1.n, 1000u) << name;
    EXPECT_LT(e1.rmse_v, 0.5 * e0.rmse_v) << name;
    EXPECT_LT(e1.rmse_v, sigma / 3.0) << name;  // ten readings a second: far better than one
    EXPECT_LT(burst.rmse_v, sigma) << name;     // the burst does not pull it
    EXPECT_LT(e1.rmse_h, 1.2 * e0.rmse_h + 0.02) << name;  // and the rest no worse
  }
  // Every record after the initialisation is offered to both estimators: the gate rejects the 30 wild ones
  // and about what its probability says of the others; those before the initialisation are counted as unused.
  for (const char* name : {"eskf", "smoother"}) {
    const nlohmann::json& b = with.stats["estimators"][name]["barometer"];
    EXPECT_GT(b["used"].get<uint64_t>(), 1500u) << b.dump();
    const uint64_t rejected = b["rejected"].value("chi2_gate", 0u);
    EXPECT_GE(rejected, 30u) << name << " " << b.dump();
    EXPECT_LE(rejected, 30u + FalseRejectionBound(b["offered"])) << name << " " << b.dump();
  }
  EXPECT_GT(with.stats["baro_unused"].get<uint64_t>(), 10u);
  EXPECT_FALSE(without.stats.contains("baro_unused"));
}

}  // namespace GINS_TEST_FILE
}  // namespace gins
