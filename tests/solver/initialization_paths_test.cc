// Each initialisation path end to end (core/initializer.h), on seeded simulated drives through a EstimatorPipeline with
// both estimators: static with and without wheels, in motion (a log that starts while driving), with and
// without a dual-antenna heading, reversing, 5 Hz and 20 Hz single-point GNSS, Earth rotation on and off.
// Every case is started with the defaults' initial-state handling (no initial-state keys exist): only the
// sensors' description changes. Thresholds are about twice the measured values (printed), so a regression
// of the path (a wrong yaw, a start much later, a yaw σ that does not cover the error) fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "drive_harness.h"
#include "test_scenarios.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kDeg = kDegToRad;

// A car on single-point GNSS: no heading, no wheels, metre-level fixes at `rate` Hz, correlated over 5 s.
SimOptions SppDrive(unsigned seed, double rate) {
  SimOptions s = test::TestDrive(seed);
  s.gnss_rate = rate;
  s.gnss_sigma_enu = Vec3(1.0, 1.0, 1.5);
  s.heading_invalid_fraction = 1.0;
  s.wheel_rate = 0.0;
  s.gnss_outages.clear();
  return s;
}

Options SppOptions(const SimOptions& sim) {
  Options o = test::TestRunOptions(sim);
  o.sensors.gnss.use_heading = false;
  o.sensors.gnss.min_sigma = 0.3;
  return o;
}

// The state at time t of a stream (nullptr: none).
const StateEstimate* StateAt(const std::vector<StateEstimate>& states, double t) {
  for (const StateEstimate& s : states) {
    if (std::abs(s.x.t - t) < 1e-9) return &s;
  }
  return nullptr;
}

struct Outcome {
  test::DriveRun run;
  double init_after = 0.0;  // s after the first record
  double yaw_error_at_init = 0.0, yaw_sigma_at_init = 0.0;  // deg
  test::DriveErrors eskf, smoother;
};

// Runs the drive and scores both estimators from `score_from` s after initialisation on.
Outcome RunAndScore(const SimOptions& sim, const Options& options, const char* name, double score_from = 30.0) {
  Outcome o;
  o.run = test::RunDriveThroughSession(sim, options);
  EXPECT_TRUE(o.run.initialized) << name;
  if (!o.run.initialized) return o;
  o.init_after = o.run.init_t - o.run.first_t;
  const nlohmann::json& init = o.run.stats["initialization"];
  o.yaw_sigma_at_init = init["yaw_sigma_deg"].get<double>();
  const StateEstimate* at_init = StateAt(o.run.eskf, o.run.init_t);
  for (size_t i = 0; i < o.run.truth_t.size(); ++i) {
    if (std::abs(o.run.truth_t[i] - o.run.init_t) < 1e-6 && at_init) {
      const NavState& x = at_init->x;
      o.yaw_error_at_init =
          WrapAngle(YawOfXAxis<double>(x.R_wb()) - YawOfXAxis<double>(o.run.truth[i].R_wb())) * kRadToDeg;
    }
  }
  const double from = o.run.init_t + score_from;
  o.eskf = test::Errors(o.run, o.run.eskf, from);
  o.smoother = test::Errors(o.run, o.run.smoother, from);
  std::printf("[ %-34s] init after %.1f s (%s, %s, witness '%s'), yaw error %.3f deg (σ %.3f)\n", name, o.init_after,
              init["start"].get<std::string>().c_str(), init["heading_source"].get<std::string>().c_str(),
              init["standstill_witness"].get<std::string>().c_str(), o.yaw_error_at_init, o.yaw_sigma_at_init);
  test::PrintErrors("eskf", o.eskf);
  test::PrintErrors("smoother", o.smoother);
  return o;
}

void ExpectCovered(const Outcome& o) {
  // The start's yaw σ is the fit's: the error lies within 4 σ of it.
  EXPECT_LT(std::abs(o.yaw_error_at_init), 4.0 * o.yaw_sigma_at_init + 0.05);
}

// Static with wheels and a heading (the reference car): initialised at the standstill by the heading.
TEST(InitializationPaths, StaticWithWheelsAndHeading) {
  const SimOptions sim = test::TestDrive(21);
  const Outcome o = RunAndScore(sim, test::TestRunOptions(sim), "static, wheels, heading");
  const nlohmann::json& init = o.run.stats["initialization"];
  EXPECT_EQ(init["start"], "standstill");
  EXPECT_EQ(init["standstill_witness"], "wheels");
  EXPECT_EQ(init["heading_source"], "dual_antenna");
  EXPECT_LT(o.init_after, 3.0);  // measured 2.0 s
  ExpectCovered(o);
  EXPECT_LT(o.eskf.rmse_h, 0.10);
  EXPECT_LT(o.smoother.rmse_h, 0.10);
  EXPECT_LT(o.eskf.rmse_yaw_deg, 0.5);
}

// Static with wheels, no heading: the standstill, then the fit once the car moves (at 20 s).
TEST(InitializationPaths, StaticWithWheelsNoHeading) {
  SimOptions sim = test::TestDrive(22);
  sim.heading_invalid_fraction = 1.0;
  Options options = test::TestRunOptions(sim);
  options.sensors.gnss.use_heading = false;
  const Outcome o = RunAndScore(sim, options, "static, wheels, no heading");
  const nlohmann::json& init = o.run.stats["initialization"];
  EXPECT_EQ(init["start"], "standstill");
  EXPECT_EQ(init["standstill_witness"], "wheels");
  EXPECT_GT(o.init_after, 20.0);
  EXPECT_LT(o.init_after, 26.0);
  ExpectCovered(o);
  EXPECT_LT(std::abs(o.yaw_error_at_init), 1.0);
  EXPECT_LT(o.eskf.rmse_h, 0.15);
  EXPECT_LT(o.smoother.rmse_h, 0.15);
  EXPECT_LT(o.eskf.rmse_yaw_deg, 1.0);
}

// A start at rest without a heading: every output from the first fix (docs/estimators.md). At rest the
// forward streams hold the standstill's position, a zero velocity and an unknown yaw, the two-sided streams
// the yaw found later (within 4 of their σ); from the standstill's end to the initialisation, the fit's
// window. Every state before the initialisation lies within 3 of its σ of the truth (95 % of them).
// outlier_t: the fix at that time moved 20 m north (none if 0).
void ExpectOutputFromTheFirstFix(const SimOptions& sim, const Options& options, const char* name,
                                 double outlier_t = 0.0) {
  const test::RecordHook hook = [&](const SimRecord& r, const std::function<void(const SimRecord&)>& feed, EstimatorPipeline&) {
    if (!r.is<GnssRecord>() || std::abs(r.get<GnssRecord>().t - outlier_t) > 1e-6) return feed(r);
    SimRecord moved = r;
    moved.get<GnssRecord>().lat_deg += 20.0 / 111111.0;
    feed(moved);
  };
  const test::DriveRun run = test::RunDriveThroughSession(sim, options, hook, true, true, true);
  ASSERT_TRUE(run.initialized) << name;
  EXPECT_GT(run.stats["rest_states_before_initialization"].get<uint64_t>(), 0u) << name;
  const double static_end = run.stats["initialization"]["static_end"].get<double>();
  EXPECT_GT(static_end, run.first_t + 10.0) << name;
  const double from = run.first_t + 1.0;  // the first fix comes within a second
  const std::pair<const char*, const std::vector<StateEstimate>*> streams[] = {
      {"eskf", &run.eskf}, {"smoother", &run.smoother}, {"eskf_rts", &run.eskf_rts}, {"batch", &run.batch}};
  for (const auto& [stream, states] : streams) {
    const double coverage = test::Coverage(run, *states, from);
    size_t before = 0, within = 0, rest = 0;
    double max_yaw_z = 0.0, max_h = 0.0, max_rest_speed = 0.0;
    const bool two_sided = states == &run.eskf_rts || states == &run.batch;
    test::ForEachAtTruth(run, *states, from, run.init_t, [&](const StateEstimate& s, size_t j) {
      const NavState& truth = run.truth[j];
      const Vec3 d = s.x.p_wb - truth.p_wb;
      ++before;
      within += std::abs(d.x()) <= 3.0 * s.sigma_p.x() && std::abs(d.y()) <= 3.0 * s.sigma_p.y() &&
                std::abs(d.z()) <= 3.0 * s.sigma_p.z();
      max_h = std::max(max_h, d.head<2>().norm());
      if (s.x.t >= static_end) return;
      ++rest;
      const double yaw_error = WrapAngle(YawOfXAxis<double>(s.x.R_wb()) - YawOfXAxis<double>(truth.R_wb()));
      if (two_sided) {
        // The backward run's standstill updates: a velocity within its σ of zero.
        max_rest_speed = std::max(max_rest_speed, s.x.v_w.norm());
        max_yaw_z = std::max(max_yaw_z, std::abs(yaw_error) / s.sigma_att.z());
      } else {
        EXPECT_EQ(s.x.v_w, Vec3::Zero()) << name << " " << stream << " t=" << s.x.t;
        EXPECT_EQ(s.sigma_att.z(), kUnknownYawSigma) << name << " " << stream;
      }
    });
    std::printf("[ %-34s] %-8s coverage %.4f, %zu states before init (%zu at rest), %zu within 3 σ, max %.3f m, "
                "rest yaw error/σ %.2f, rest speed %.4f m/s\n",
                name, stream, coverage, before, rest, within, max_h, max_yaw_z, max_rest_speed);
    EXPECT_GE(coverage, 0.99) << name << " " << stream;
    EXPECT_GT(rest, 0u) << name << " " << stream;
    EXPECT_GE(within, 0.95 * static_cast<double>(before)) << name << " " << stream;
    if (two_sided) {
      EXPECT_LT(max_yaw_z, 4.0) << name << " " << stream;
      EXPECT_LT(max_rest_speed, 0.02) << name << " " << stream;
    }
  }
}

// One drive per test: three in one took over a minute under the sanitizers.
SimOptions AtRestWithoutHeading() {
  SimOptions sim = test::TestDrive(31);
  sim.heading_invalid_fraction = 1.0;
  return sim;
}

Options WithoutHeading(const SimOptions& sim) {
  Options options = test::TestRunOptions(sim);
  options.sensors.gnss.use_heading = false;
  return options;
}

TEST(InitializationPaths, AtRestWithoutHeadingEveryOutputFromTheFirstFix) {
  const SimOptions sim = AtRestWithoutHeading();
  ExpectOutputFromTheFirstFix(sim, WithoutHeading(sim), "rest, wheels, no heading");
}

TEST(InitializationPaths, AtRestAnOutlierAmongTheStandstillsFixesIsNotInItsPosition) {
  // A gross outlier among the standstill's fixes (20 m north at 8 s).
  const SimOptions sim = AtRestWithoutHeading();
  ExpectOutputFromTheFirstFix(sim, WithoutHeading(sim), "rest, wheels, no heading, an outlier", sim.start_time + 8.0);
}

TEST(InitializationPaths, AtRestOnSinglePointFixesWithoutWheelsEveryOutputFromTheFirstFix) {
  const SimOptions spp = SppDrive(32, 5.0);
  ExpectOutputFromTheFirstFix(spp, SppOptions(spp), "rest, no wheels, SPP 5 Hz");
}

// A start that the fit's window does not reach back to (docs/estimators.md, "Initialisation"): the car
// stands 20 s, drives off, and the IMU drops out for 0.6 s at 20.8 s (beyond imu.max_gap_s), so the
// initialiser starts again after the dropout, in motion. Every output still covers the log from the first
// fix: the forward streams the standstill as it comes and, at the initialisation, the backward run over
// the drive-off and the dropout (solver/pre_init_backward.h); the two-sided streams the backward run from
// their own first state. Before the initialisation 95 % of the states lie within 3 of their σ of the truth.
TEST(InitializationPaths, AWindowThatDoesNotReachTheFirstFixEveryOutputFromTheFirstFix) {
  SimOptions sim = test::TestDrive(33);
  sim.heading_invalid_fraction = 1.0;
  Options options = test::TestRunOptions(sim);
  options.sensors.gnss.use_heading = false;
  const double drop0 = sim.start_time + 20.8, drop1 = drop0 + 0.6;
  const test::RecordHook hook = [&](const SimRecord& r, const std::function<void(const SimRecord&)>& feed,
                                    EstimatorPipeline&) {
    if (r.is<ImuSample>() && r.get<ImuSample>().t >= drop0 && r.get<ImuSample>().t < drop1) return;
    feed(r);
  };
  const test::DriveRun run = test::RunDriveThroughSession(sim, options, hook, true, true, true);
  ASSERT_TRUE(run.initialized);
  EXPECT_EQ(run.stats["initialization"]["start"], "moving");
  EXPECT_GT(run.stats["initialization"]["window_start"].get<double>(), drop1);
  const double from = run.first_t + 1.0;  // the first fix comes within a second
  const std::pair<const char*, const std::vector<StateEstimate>*> streams[] = {
      {"eskf", &run.eskf}, {"smoother", &run.smoother}, {"eskf_rts", &run.eskf_rts}, {"batch", &run.batch}};
  for (const auto& [stream, states] : streams) {
    // The dropout's IMU epochs have no truth sample: coverage counts the others.
    const double coverage = test::Coverage(run, *states, from);
    size_t before = 0, within = 0;
    double max_h = 0.0;
    test::ForEachAtTruth(run, *states, from, run.init_t, [&](const StateEstimate& s, size_t j) {
      const Vec3 d = s.x.p_wb - run.truth[j].p_wb;
      ++before;
      within += (d.cwiseAbs().array() <= 3.0 * s.sigma_p.array()).all();
      max_h = std::max(max_h, d.head<2>().norm());
    });
    std::printf("[ window after a dropout ] %-8s coverage %.4f, %zu states before init, %zu within 3 σ, max %.3f m\n",
                stream, coverage, before, within, max_h);
    EXPECT_GE(coverage, 0.99) << stream;
    EXPECT_GE(within, 0.95 * static_cast<double>(before)) << stream;
    EXPECT_LT(max_h, 0.5) << stream;
  }
}

// Static without wheels, single-point GNSS with Doppler velocity: the GNSS velocity witnesses the standstill.
TEST(InitializationPaths, StaticWithoutWheelsGnssVelocityWitness) {
  SimOptions sim = SppDrive(23, 5.0);
  sim.gnss_velocity_sigma = Vec3(0.05, 0.05, 0.1);
  const Outcome o = RunAndScore(sim, SppOptions(sim), "static, no wheels, GVEL, SPP 5 Hz");
  const nlohmann::json& init = o.run.stats["initialization"];
  EXPECT_EQ(init["start"], "standstill");
  EXPECT_EQ(init["standstill_witness"], "gnss_velocity");
  EXPECT_GT(o.init_after, 20.0);
  EXPECT_LT(o.init_after, 28.0);
  ExpectCovered(o);
  EXPECT_LT(std::abs(o.yaw_error_at_init), 2.0);
  EXPECT_LT(o.eskf.rmse_h, 0.6);
  EXPECT_LT(o.smoother.rmse_h, 0.6);
}

// Static without wheels and without GNSS velocity: the fixes themselves must agree (a few seconds at 1 m).
TEST(InitializationPaths, StaticWithoutWheelsGnssPositionWitness) {
  const SimOptions sim = SppDrive(24, 5.0);
  const Outcome o = RunAndScore(sim, SppOptions(sim), "static, no wheels, SPP 5 Hz");
  const nlohmann::json& init = o.run.stats["initialization"];
  EXPECT_EQ(init["start"], "standstill");
  EXPECT_EQ(init["standstill_witness"], "gnss_position");
  EXPECT_GT(o.init_after, 20.0);
  EXPECT_LT(o.init_after, 30.0);
  ExpectCovered(o);
  EXPECT_LT(std::abs(o.yaw_error_at_init), 2.0);
  EXPECT_LT(o.eskf.rmse_h, 0.8);
  EXPECT_LT(o.smoother.rmse_h, 0.8);
}

// A log that starts while driving (TestDrive from 22 s: accelerating at 2 m/s), 20 Hz single-point fixes.
TEST(InitializationPaths, InMotionSpp20Hz) {
  SimOptions sim = SppDrive(25, 20.0);
  sim.log_start = 22.0;
  const Outcome o = RunAndScore(sim, SppOptions(sim), "in motion, SPP 20 Hz");
  EXPECT_EQ(o.run.stats["initialization"]["start"], "moving");
  EXPECT_LT(o.init_after, 10.0);
  ExpectCovered(o);
  EXPECT_LT(std::abs(o.yaw_error_at_init), 2.0);
  EXPECT_LT(o.eskf.rmse_h, 0.8);
  EXPECT_LT(o.smoother.rmse_h, 0.8);
  EXPECT_LT(o.eskf.rmse_yaw_deg, 2.0);
}

// The same at 5 Hz, on the flat Earth (Earth rotation off in both the simulation and gins).
TEST(InitializationPaths, InMotionSpp5HzFlatEarth) {
  SimOptions sim = SppDrive(26, 5.0);
  sim.log_start = 22.0;
  sim.earth_rotation = false;
  Options options = SppOptions(sim);
  options.sensors.gravity.earth_rotation = false;
  const Outcome o = RunAndScore(sim, options, "in motion, SPP 5 Hz, flat Earth");
  EXPECT_EQ(o.run.stats["initialization"]["start"], "moving");
  EXPECT_LT(o.init_after, 12.0);
  ExpectCovered(o);
  EXPECT_LT(std::abs(o.yaw_error_at_init), 2.0);
  EXPECT_LT(o.eskf.rmse_h, 0.8);
  EXPECT_LT(o.smoother.rmse_h, 0.8);
}

// In motion with RTK fixes and a dual-antenna heading (and wheels): the heading gives yaw, the GNSS track
// roll and pitch.
TEST(InitializationPaths, InMotionWithHeading) {
  SimOptions sim = test::TestDrive(27);
  sim.log_start = 40.0;  // in the left turn at 10 m/s
  sim.gnss_outages.clear();
  const Outcome o = RunAndScore(sim, test::TestRunOptions(sim), "in motion, RTK, heading");
  const nlohmann::json& init = o.run.stats["initialization"];
  EXPECT_EQ(init["start"], "moving");
  EXPECT_EQ(init["heading_source"], "dual_antenna");
  EXPECT_LT(o.init_after, 8.0);
  ExpectCovered(o);
  EXPECT_LT(std::abs(o.yaw_error_at_init), 0.5);
  EXPECT_LT(o.eskf.rmse_h, 0.1);
  EXPECT_LT(o.smoother.rmse_h, 0.1);
}

// Reversing at the start of the log: the car backs up at 1.5 m/s (the body faces the other way than the
// course), then drives off forward. The fit tells backward from forward by the IMU's accelerations.
TEST(InitializationPaths, ReversingAtTheStart) {
  SimOptions sim = SppDrive(28, 10.0);
  sim.gnss_sigma_enu = Vec3(0.3, 0.3, 0.5);
  sim.segments = {
      {3.0, 0.5, 0.0, 0.0, true},     // backing up
      {8.0, 0.0, 5.0 * kDeg, 0.0, true},  // reversing round a corner
      {4.0, -0.5, 0.0, 0.0, true},    // brake to a stop (the ramps leave 0.25 m/s after 3 s)
      {2.0, 0.0, 0.0, 0.0, false},
      {10.0, 1.0, 0.0, 0.0},          // off forward
      {20.0, 0.0, -4.0 * kDeg, 0.0},
      {30.0, 0.0, 0.0, 0.0},
  };
  sim.log_start = 1.0;
  const Outcome o = RunAndScore(sim, SppOptions(sim), "reversing at the start", 10.0);
  ExpectCovered(o);
  EXPECT_LT(std::abs(o.yaw_error_at_init), 3.0);  // not 180°
  EXPECT_LT(o.eskf.max_yaw_deg, 5.0);
  EXPECT_LT(o.smoother.max_yaw_deg, 5.0);
}

// A constant-speed cruise without encoders is never taken for a stop: the IMU is as quiet as when parked,
// but the GNSS says 5 m/s. Initialisation must not assume zero velocity, and no zero-velocity update runs.
TEST(InitializationPaths, CruiseIsNotAStandstill) {
  SimOptions sim = SppDrive(29, 5.0);
  sim.segments = {{5.0, 1.0, 0.0, 0.0}, {60.0, 0.0, 0.0, 0.0}, {20.0, 0.0, 4.5 * kDeg, 0.0}, {30.0, 0.0, 0.0, 0.0}};
  sim.log_start = 10.0;  // cruising at 5 m/s from the first record
  const Outcome o = RunAndScore(sim, SppOptions(sim), "cruise, no wheels", 10.0);
  const nlohmann::json& init = o.run.stats["initialization"];
  EXPECT_EQ(init["start"], "moving");
  EXPECT_EQ(o.run.stats["standstill_updates"].get<uint64_t>(), 0u);
  ExpectCovered(o);
  const StateEstimate* at_init = StateAt(o.run.eskf, o.run.init_t);
  ASSERT_NE(at_init, nullptr);
  for (size_t i = 0; i < o.run.truth_t.size(); ++i) {
    if (std::abs(o.run.truth_t[i] - o.run.init_t) < 1e-6) {
      EXPECT_LT((at_init->x.v_w - o.run.truth[i].v_w).norm(), 0.5);
    }
  }
}

// A slow rover: 0.3 m/s on 10 Hz metre-level single-point fixes, no wheels, no heading; a standing start,
// then a straight, a quarter turn and a straight. The yaw takes a full window of the slow track.
TEST(InitializationPaths, SlowRoverSpp) {
  SimOptions sim = SppDrive(30, 10.0);
  sim.segments = {
      {10.0, 0.0, 0.0, 0.0},         // standing
      {3.5, 0.1, 0.0, 0.0},          // to 0.3 m/s
      {40.0, 0.0, 0.0, 0.0},
      {30.0, 0.0, 3.0 * kDeg, 0.0},  // quarter turn
      {60.0, 0.0, 0.0, 0.0},
  };
  const Outcome o = RunAndScore(sim, SppOptions(sim), "slow rover, SPP 10 Hz");
  EXPECT_EQ(o.run.stats["initialization"]["start"], "standstill");
  ExpectCovered(o);
  EXPECT_LT(o.init_after, 40.0);  // measured 30.2 s: a full window of the slow track
  EXPECT_LT(o.eskf.rmse_h, 0.4);
  EXPECT_LT(o.smoother.rmse_h, 0.25);
  EXPECT_LT(o.eskf.max_yaw_deg, 2.0);
  EXPECT_LT(o.smoother.max_yaw_deg, 2.0);
}

}  // namespace
}  // namespace gins
