// Fault injection, continued (fault_injection_test.cc has the IMU and time-stamp faults and the conventions):
// GNSS jumps, wheels that stop, a frozen heading, a logger that pauses, and logs that end mid-initialisation.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "estimators_from_options.h"
#include "fault_harness.h"

namespace gins {
namespace GINS_TEST_FILE {

using test::DriveRun;
using test::Editing;
using test::ExpectRecovery;
using test::FaultDrive;
using test::kFaultBound;

uint64_t Resets(const DriveRun& run, const char* estimator) {
  return run.stats["estimators"][estimator]["watchdog"]["count"].get<uint64_t>();
}

// The drift in the GNSS outage [outage, outage_end] of each estimator of `run` is within 1.5× (+0.5 m) of the
// same drive's without wheels at all: wheels that fail are at worst ignored.
void ExpectOutageDriftAsWithoutWheels(const SimOptions& sim, const DriveRun& run, double outage, double outage_end,
                                      const char* fault) {
  Options no_wheels = test::TestRunOptions(sim);
  no_wheels.sensors.wheel.enabled = false;
  const DriveRun reference = test::RunDriveThroughSession(sim, no_wheels);
  ASSERT_TRUE(reference.initialized);
  for (const auto& [name, states, ref] : {std::tuple{"eskf", &run.eskf, &reference.eskf},
                                         std::tuple{"smoother", &run.smoother, &reference.smoother}}) {
    const double drift = test::HorizontalErrors(run, *states, outage, outage_end).max_h;
    const double ref_drift = test::HorizontalErrors(reference, *ref, outage, outage_end).max_h;
    std::printf("%s: outage drift %.3f m with %s, %.3f m without wheels\n", name, drift, fault, ref_drift);
    EXPECT_LT(drift, 1.5 * ref_drift + 0.5) << name;
  }
}

// A GNSS jump of 1 km that lasts (the receiver's positions move for good at 60 s: a new datum, a wrong base
// station). Expected: every fix is rejected (χ²) while the estimate coasts on the IMU and wheels; after
// watchdog.max_reject_s (15 s) the watchdog re-initialises from the fix (one reset, reason gnss_rejected) and
// the estimate follows the moved positions: within the bound of them 20 s after the jump.
TEST(FaultInjection, GnssJumpOfOneKilometreThatLasts) {
  const SimOptions sim = FaultDrive(21, 110.0);
  const double t0 = sim.start_time + 60.0;
  const Vec3 jump(600.0, -800.0, 0.0);
  const DriveRun run = test::RunDriveThroughSession(sim, test::TestRunOptions(sim), Editing([&](SimRecord* r) {
    if (r->is<GnssRecord>() && r->t() >= t0) test::Displace(sim, jump, &r->get<GnssRecord>());
    return true;
  }));
  ASSERT_TRUE(run.initialized);
  test::ExpectSaneOutputs(run);
  for (const char* e : {"eskf", "smoother"}) {
    EXPECT_EQ(Resets(run, e), 1u) << e;
    EXPECT_EQ(run.stats["estimators"][e]["watchdog"]["resets"][0]["reason"], "gnss_rejected") << e;
  }
  for (const std::vector<StateEstimate>* states : {&run.eskf, &run.smoother}) {  // coasting, not pulled
    EXPECT_LT(test::HorizontalErrors(run, *states, t0, t0 + 14.0).max_h, 1.0);
  }
  ExpectRecovery("GNSS jump of 1 km that lasts", run, t0, t0, sim.start_time + 110.0, 20.0, kFaultBound, jump);
}

// A GNSS jump of 1 km that comes back (loss of lock), for 5 s and for 30 s. Expected: a jump shorter than
// watchdog.max_reject_s is rejected fix by fix, no reset, the estimate never leaves the bound; a longer one is
// taken after 15 s (a reset onto the jumped positions), and when the fixes come back the same happens again:
// within the bound 20 s after the jump ends, two resets.
TEST(FaultInjection, GnssJumpOfOneKilometreThatComesBack) {
  for (double d : {5.0, 30.0}) {
    SCOPED_TRACE("jump for " + std::to_string(d) + " s");
    const SimOptions sim = FaultDrive(22, 130.0);
    const double t0 = sim.start_time + 60.0, t1 = t0 + d;
    const DriveRun run = test::RunDriveThroughSession(sim, test::TestRunOptions(sim), Editing([&](SimRecord* r) {
      GnssRecord* fix = r->get_if<GnssRecord>();
      if (fix && r->t() >= t0 && r->t() < t1) test::Displace(sim, Vec3(0.0, 1000.0, 0.0), fix);
      return true;
    }));
    ASSERT_TRUE(run.initialized);
    test::ExpectSaneOutputs(run);
    for (const char* e : {"eskf", "smoother"}) EXPECT_EQ(Resets(run, e), d < 15.0 ? 0u : 2u) << e;
    ExpectRecovery("GNSS jump of 1 km for " + std::to_string(static_cast<int>(d)) + " s", run, t0, d < 15.0 ? t0 : t1,
                   sim.start_time + 130.0, d < 15.0 ? 0.0 : 20.0);
  }
}

// The wheels stop reporting at 40 s (no more ODOM records), before a stop (105-115 s) and a 20 s GNSS outage
// (125-145 s). Expected: as a log without wheels from then on: the stop is detected from the quiet IMU alone,
// the outage drift at most that of a run without wheels (×1.5 + 0.5 m), within the bound 5 s after the
// outage.
TEST(FaultInjection, WheelsStopReporting) {
  const SimOptions sim = FaultDrive(23, 155.0, /*keep_outage=*/true);
  const double t0 = sim.start_time + 40.0, outage = sim.start_time + 125.0, outage_end = outage + 20.0;
  const DriveRun run = test::RunDriveThroughSession(sim, test::TestRunOptions(sim), Editing([&](SimRecord* r) {
    return !(r->is<WheelRecord>() && r->t() >= t0);
  }));
  ASSERT_TRUE(run.initialized);
  test::ExpectSaneOutputs(run);
  ExpectOutageDriftAsWithoutWheels(sim, run, outage, outage_end, "the wheels silent from 40 s");
  EXPECT_GT(run.stats["standstill_updates"].get<uint64_t>(), 50u);
  ExpectRecovery("wheels stop reporting (then a 20 s GNSS outage)", run, outage, outage_end, sim.start_time + 155.0, 5.0);
}

// The dual-antenna heading is valid but constant: frozen at its value at the start (right while standing,
// wrong by up to 90° once the car has turned). Expected: the first turns make the heading disagree with the
// gyro; the ESKF's χ² gate rejects it from then on (counted), the smoother's robust loss leaves it no weight;
// the yaw follows the gyro and the fixes (error below 1°), the position stays within the bound.
TEST(FaultInjection, HeadingValidButConstant) {
  const SimOptions sim = FaultDrive(24, 120.0);
  auto frozen = std::make_shared<double>(-1.0);
  const DriveRun run = test::RunDriveThroughSession(sim, test::TestRunOptions(sim), Editing([&](SimRecord* r) {
    if (r->is<GnssRecord>()) {
      if (*frozen < 0.0 && r->get<GnssRecord>().heading_valid) *frozen = r->get<GnssRecord>().heading_deg;
      r->get<GnssRecord>().heading_valid = true;
      r->get<GnssRecord>().heading_deg = *frozen < 0.0 ? 0.0 : *frozen;
    }
    return true;
  }));
  ASSERT_TRUE(run.initialized);
  test::ExpectSaneOutputs(run);
  EXPECT_GT(run.stats["estimators"]["eskf"]["gnss_heading"]["rejected"].value("chi2_gate", 0u), 30u);
  for (const auto& [name, states] : {std::pair{"eskf", &run.eskf}, std::pair{"smoother", &run.smoother}}) {
    const test::DriveErrors e = test::Errors(run, *states, run.init_t + 5.0);
    test::PrintErrors(name, e);
    EXPECT_LT(e.max_yaw_deg, 1.0) << name;
  }
  ExpectRecovery("heading valid but constant", run, run.init_t, run.init_t + 5.0, sim.start_time + 120.0, 0.0);
}

// The logger pauses: no record of any type for 1, 2, 5, 10 and 60 s while driving (from 50 s). Expected: both
// coast across the IMU gap (counted) with the uncertainty of an unknown motion (estimator_common.h, kImuGap*); at
// the first fix after it the position σ has grown past the fixes' error, so the fix is taken (after 60 s,
// past watchdog.max_position_sigma_m: a re-initialisation from it, the lost yaw from the dual-antenna
// heading); within the bound 5 s after the records return.
TEST(FaultInjection, LoggerPause) {
  for (double d : {1.0, 2.0, 5.0, 10.0, 60.0}) {
    SCOPED_TRACE("pause " + std::to_string(d) + " s");
    const SimOptions sim = FaultDrive(25, 140.0);
    const double t0 = sim.start_time + 50.0, t1 = t0 + d;
    const DriveRun run = test::RunDriveThroughSession(sim, test::TestRunOptions(sim), Editing([&](SimRecord* r) {
      return !(r->t() > t0 && r->t() < t1);
    }));
    ASSERT_TRUE(run.initialized);
    test::ExpectSaneOutputs(run);
    ExpectRecovery("logger pause " + std::to_string(static_cast<int>(d)) + " s", run, t0, t1, sim.start_time + 140.0,
                   5.0);
  }
}

// A 60 s logger pause on a log whose fixes carry no heading (gnss.use_heading: false). Expected: at the first
// fix after it the yaw is lost (σ far beyond 20°), and there is no heading to take it from: both wait for
// the next fix (a second), then re-initialise with velocity and yaw from the two fixes' course (a car
// drives along its body axis); within the bound 5 s after the records return. Without NHC (not a car)
// the course says nothing of the yaw, and the reset keeps it, as before.
TEST(FaultInjection, LongLoggerPauseWithoutHeading) {
  const SimOptions sim = FaultDrive(25, 140.0);
  Options options = test::TestRunOptions(sim);
  options.sensors.gnss.use_heading = false;
  const double t0 = sim.start_time + 50.0, t1 = t0 + 60.0;
  std::vector<double> fixes;  // the times of the fixes the session got
  const DriveRun run = test::RunDriveThroughSession(sim, options, Editing([&](SimRecord* r) {
    const bool kept = !(r->t() > t0 && r->t() < t1);
    if (kept && r->is<GnssRecord>()) fixes.push_back(r->t());
    return kept;
  }));
  ASSERT_TRUE(run.initialized);
  test::ExpectSaneOutputs(run);
  ExpectRecovery("logger pause 60 s, no heading", run, t0, t1, sim.start_time + 140.0, 5.0);
  for (const char* name : {"eskf", "smoother"}) {
    SCOPED_TRACE(name);
    const nlohmann::json& resets = run.stats["estimators"][name]["watchdog"]["resets"];
    ASSERT_GE(resets.size(), 1u);
    EXPECT_NEAR(resets[0]["time"].get<double>(), t1 + 1.0, 1e-6);  // the second fix after the pause
    EXPECT_EQ(resets[0]["reason"], "covariance");
    // Every fix after the initialisation is counted, the two the reset took included.
    const nlohmann::json& counts = run.stats["estimators"][name]["gnss_position"];
    EXPECT_EQ(counts["offered"].get<size_t>(),
              static_cast<size_t>(std::count_if(fixes.begin(), fixes.end(), [&](double t) { return t > run.init_t; })));
  }
}

// The wheel encoders count zero from 40 s on while the car drives (a stuck encoder), then a 20 s GNSS outage
// (125-145 s). Expected: the zero speeds are outliers (rejected and counted), the outage drift at most that of
// a run without wheels (×1.5 + 0.5 m), within the bound 5 s after the outage.
TEST(FaultInjection, WheelsCountZeroWhileMoving) {
  const SimOptions sim = FaultDrive(27, 155.0, /*keep_outage=*/true);
  const double t0 = sim.start_time + 40.0, outage = sim.start_time + 125.0, outage_end = outage + 20.0;
  const DriveRun run = test::RunDriveThroughSession(sim, test::TestRunOptions(sim), Editing([&](SimRecord* r) {
    WheelRecord* wheel = r->get_if<WheelRecord>();
    if (wheel && r->t() >= t0) wheel->left_pulses = wheel->right_pulses = 0.0;
    return true;
  }));
  ASSERT_TRUE(run.initialized);
  test::ExpectSaneOutputs(run);
  ExpectOutageDriftAsWithoutWheels(sim, run, outage, outage_end, "the wheels counting zero from 40 s");
  for (const char* name : {"eskf", "smoother"}) {
    EXPECT_GT(run.stats["estimators"][name]["wheel"]["rejected"].value("chi2_gate", 0u), 100u) << name;
  }
  ExpectRecovery("wheels count zero while moving", run, t0, outage_end, sim.start_time + 155.0, 5.0);
}

// A log that ends during the initialisation. Expected: Finish throws RunError whose one-line message says why
// (too few fixes yet; a standstill found but too few fixes after it) and no state was emitted but the states at
// rest (solver/pre_init_output.h: zero velocity; the drive has a heading, so its yaw); a log that ends 0.5 s after
// the initialisation has its states, all sane.
TEST(FaultInjection, LogEndsMidInitialisation) {
  const struct {
    double end;  // s after the start
    const char* message;
  } cases[] = {{1.5, "waiting for more GNSS fixes"}, {1.995, "standstill found"}};
  for (const auto& c : cases) {
    SCOPED_TRACE("log of " + std::to_string(c.end) + " s");
    const SimOptions sim = FaultDrive(26, 30.0);
    const Options options = test::TestRunOptions(sim);
    Simulator simulator(sim);
    EstimatorPipeline session(options.sensors, options.init, options.standstill);
    size_t not_at_rest = 0;
    const StateCallback count = [&](const StateEstimate& s) { not_at_rest += !(s.x.v_w.isZero(0.0)); };
    session.AddEstimator(test::MakeEskf(options, count));
    session.AddEstimator(test::MakeSmoother(options, count, count));
    SimRecord r;
    while (simulator.Next(&r) && r.t() < sim.start_time + c.end) test::FeedSession(&session, r);
    ASSERT_FALSE(session.initialized());
    try {
      session.Finish();
      ADD_FAILURE() << "Finish did not throw";
    } catch (const RunError& e) {
      const std::string what = e.what();
      std::printf("log of %.3f s: RunError: %s\n", c.end, what.c_str());
      EXPECT_NE(what.find(c.message), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos);
    }
    EXPECT_EQ(not_at_rest, 0u);
    EXPECT_EQ(session.Stats()["rest_states_before_initialization"].get<uint64_t>() > 0, c.end > 1.9);
  }
  const SimOptions sim = FaultDrive(26, 30.0);
  auto end = std::make_shared<double>(1e300);
  const DriveRun run = test::RunDriveThroughSession(
      sim, test::TestRunOptions(sim),
      [end](const SimRecord& r, const std::function<void(const SimRecord&)>& feed, EstimatorPipeline& session) {
        if (r.t() >= *end) return;
        feed(r);
        if (*end > 1e299 && session.initialized()) *end = r.t() + 0.5;
      });
  ASSERT_TRUE(run.initialized);
  EXPECT_GT(run.eskf.size(), 40u);
  EXPECT_GT(run.smoother.size(), 0u);
  test::ExpectSaneOutputs(run);
}

}  // namespace
}  // namespace gins
