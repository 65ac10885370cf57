// Both estimators end to end on seeded simulated drives with field damage put into the measurement stream:
// a burst of wild GNSS fixes, fixes noisier than stated, a real GNSS position step that persists (the
// watchdog), a long parked stop without GNSS (standstill updates), and a gap in the IMU stream.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "core/geodesy.h"
#include "core/sim/simulator.h"
#include "estimators_from_options.h"
#include "fault_harness.h"
#include "solver/eskf.h"
#include "solver/estimator_pipeline.h"
#include "solver/smoother.h"
#include "sim_feed.h"
#include "test_scenarios.h"

namespace gins {
namespace GINS_TEST_FILE {

// A record of the simulated stream may be changed (return true) or dropped (return false) before the
// session sees it.
using Edit = std::function<bool(SimRecord*)>;

struct Timed {
  double t;
  Vec3 p;
};

struct Output {
  std::vector<StateEstimate> eskf, smoother;   // ESKF at IMU rate; smoother final stream
  std::vector<double> truth_t;
  std::vector<Vec3> truth_p;
  nlohmann::json eskf_stats, smoother_stats, session_stats;
  double init_time = 0.0;

  Vec3 TruthAt(double t) const {
    const auto it = std::lower_bound(truth_t.begin(), truth_t.end(), t - 1e-6);
    const size_t i = std::min<size_t>(static_cast<size_t>(it - truth_t.begin()), truth_t.size() - 1);
    return truth_p[i];
  }
};

Output RunDrive(const SimOptions& sim, const Options& options, const Edit& edit) {
  Output out;
  Simulator simulator(sim);
  EstimatorPipeline session(options.sensors, options.init, options.standstill);
  auto eskf = test::MakeEskf(options, [&](const StateEstimate& e) { out.eskf.push_back(e); });
  auto smoother = test::MakeSmoother(
      options, [&](const StateEstimate& e) { out.smoother.push_back(e); }, nullptr);
  const Eskf* eskf_ptr = eskf.get();
  const Smoother* smoother_ptr = smoother.get();
  session.AddEstimator(std::move(eskf));
  session.AddEstimator(std::move(smoother));
  SimRecord rec;
  while (simulator.Next(&rec)) {
    if (rec.is<ImuSample>()) {
      out.truth_t.push_back(rec.get<ImuSample>().t);
      out.truth_p.push_back(rec.truth.p_wb);
    }
    if (edit && !edit(&rec)) continue;
    test::FeedSession(&session, rec);
  }
  session.Finish();
  out.eskf_stats = eskf_ptr->Stats();
  out.smoother_stats = smoother_ptr->Stats();
  out.session_stats = session.Stats();
  out.init_time = session.init_result().x0.t;
  return out;
}

using test::Displace;
using test::Shortened;

// Largest horizontal error over states with t in [t0, t1], against the truth shifted by `offset`.
double MaxHorizontalError(const Output& out, const std::vector<StateEstimate>& states, double t0, double t1,
                          const Vec3& offset = Vec3::Zero()) {
  double worst = 0.0;
  size_t n = 0;
  for (const StateEstimate& e : states) {
    if (e.x.t < t0 || e.x.t > t1) continue;
    EXPECT_TRUE(e.x.AllFinite());
    worst = std::max(worst, (e.x.p_wb - out.TruthAt(e.x.t) - offset).head<2>().norm());
    ++n;
  }
  EXPECT_GT(n, 0u) << "no states in [" << t0 << ", " << t1 << "]";
  return worst;
}

// Estimated position nearest to t.
Vec3 PositionAt(const std::vector<StateEstimate>& states, double t) {
  const StateEstimate* best = nullptr;
  for (const StateEstimate& e : states) {
    if (best == nullptr || std::abs(e.x.t - t) < std::abs(best->x.t - t)) best = &e;
  }
  return best->x.p_wb;
}

// The largest horizontal error of the ESKF and of the smoother within 30 s of a burst, printed.
std::pair<double, double> ErrorsAroundBurst(const Output& out, const std::vector<double>& burst, unsigned seed) {
  const double e_eskf = MaxHorizontalError(out, out.eskf, burst.front() - 30.0, burst.back() + 30.0);
  const double e_smoother = MaxHorizontalError(out, out.smoother, burst.front() - 30.0, burst.back() + 30.0);
  std::printf("seed %u: max horizontal error within 30 s of the burst: eskf %.4f m, smoother %.4f m\n", seed,
              e_eskf, e_smoother);
  return {e_eskf, e_smoother};
}

// 8 consecutive fixes displaced by 50 m while driving (uphill at ~10-14 m/s): both estimators reject
// every one of them, list their times, and the trajectory around the burst is not pulled.
TEST(RobustnessEndToEnd, BurstOfEightWildFixesIsRejectedByBothEstimators) {
  for (unsigned seed : {1u, 2u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const SimOptions sim = Shortened(test::TestDrive(seed), 100.0);
    const Options options = test::TestRunOptions(sim);
    const double burst_start = sim.start_time + 60.0;  // elapsed 60..67 s
    std::vector<double> burst;
    const Output out = RunDrive(sim, options, [&](SimRecord* r) {
      if (r->is<GnssRecord>() && r->get<GnssRecord>().t >= burst_start && burst.size() < 8) {
        Displace(sim, Vec3(30.0, -40.0, 0.0), &r->get<GnssRecord>());  // 50 m
        burst.push_back(r->get<GnssRecord>().t);
      }
      return true;
    });
    ASSERT_EQ(burst.size(), 8u);
    const auto [e_eskf, e_smoother] = ErrorsAroundBurst(out, burst, seed);
    EXPECT_LT(e_eskf, 0.5);
    EXPECT_LT(e_smoother, 0.5);
    for (const nlohmann::json* stats : {&out.eskf_stats, &out.smoother_stats}) {
      const nlohmann::json& g = (*stats)["gnss_position"];
      std::printf("  gnss_position %s\n", g.dump().c_str());
      EXPECT_EQ(g["rejected"].value("chi2_gate", 0u), 8u);
      EXPECT_EQ(g["rejected_times"].get<std::vector<double>>(), burst);
      EXPECT_EQ((*stats)["watchdog"]["count"].get<size_t>(), 0u);  // a burst is not a divergence
    }
  }
}

// 8 consecutive fixes alternating ±55 m north (they never agree with one another, so the gate is never
// widened for them), each with its dual-antenna heading still valid: the headings join the window while
// the fixes are rejected. Both estimators reject exactly the 8, no watchdog fires and the track is not
// pulled. (The window used to make a keyframe per heading without solving it, and so checked the fix after
// the burst against a covariance 8 s old: it rejected true fixes after a burst.)
TEST(RobustnessEndToEnd, AlternatingBurstCostsOnlyTheBurst) {
  for (unsigned seed : {1u, 2u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const SimOptions sim = Shortened(test::TestDrive(seed), 100.0);
    const Options options = test::TestRunOptions(sim);
    const double burst_start = sim.start_time + 60.0;
    std::vector<double> burst;
    const Output out = RunDrive(sim, options, [&](SimRecord* r) {
      if (r->is<GnssRecord>() && r->get<GnssRecord>().t >= burst_start && burst.size() < 8) {
        Displace(sim, Vec3(0.0, burst.size() % 2 == 0 ? 55.0 : -55.0, 0.0), &r->get<GnssRecord>());
        burst.push_back(r->get<GnssRecord>().t);
      }
      return true;
    });
    ASSERT_EQ(burst.size(), 8u);
    for (const nlohmann::json* stats : {&out.eskf_stats, &out.smoother_stats}) {
      const nlohmann::json& g = (*stats)["gnss_position"];
      std::printf("  gnss_position %s\n", g.dump().c_str());
      EXPECT_EQ(g["rejected_times"].get<std::vector<double>>(), burst);
      EXPECT_EQ((*stats)["watchdog"]["count"].get<size_t>(), 0u);
    }
    // Every keyframe was solved (the first is the initial one), so no check used a stale covariance.
    EXPECT_GE(out.smoother_stats["solves"].get<uint64_t>() + 1, out.smoother_stats["keyframes"].get<uint64_t>());
    const auto [e_eskf, e_smoother] = ErrorsAroundBurst(out, burst, seed);
    EXPECT_LT(e_eskf, 0.2);
    EXPECT_LT(e_smoother, 0.2);
  }
}

// Every fix stated four times more precise than it is (σ 5 mm, noise 2 cm horizontally), as a hand-held
// RTK receiver or a vibrating mount gives: gated at the stated σ, a third of the good fixes would be
// rejected, and each rejection would let the estimate drift until the next. The gate learns the fixes'
// spread from the ones it accepts (GateConsistency) and then keeps every one; the track stays at the
// fixes' real accuracy.
TEST(RobustnessEndToEnd, FixesNoisierThanStatedAreKept) {
  for (unsigned seed : {1u, 2u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const SimOptions sim = Shortened(test::TestDrive(seed), 100.0);
    const Options options = test::TestRunOptions(sim);
    const Output out = RunDrive(sim, options, [&](SimRecord* r) {
      if (r->is<GnssRecord>()) r->get<GnssRecord>().sigma_enu /= 4.0;
      return true;
    });
    for (const nlohmann::json* stats : {&out.eskf_stats, &out.smoother_stats}) {
      const nlohmann::json& g = (*stats)["gnss_position"];
      const double offered = g["offered"].get<double>();
      const double used = g["used"].get<double>();
      std::printf("  gnss_position used %.0f of %.0f, gate scale %s, init %.1f, rejected %s\n", used, offered,
                  (*stats)["gnss_gate_scale"].dump().c_str(), out.init_time, g["rejected_times"].dump().c_str());
      // The gate learns from the last 21 fixes it accepted: at 1 Hz, within the first 25 s after
      // initialisation (where the initial covariance still covers the fixes' spread).
      EXPECT_GT(used, 0.8 * offered);
      for (double t : g["rejected_times"].get<std::vector<double>>()) EXPECT_LT(t, out.init_time + 25.0);
      EXPECT_GT((*stats)["gnss_gate_scale"]["max"].get<double>(), 4.0);
      EXPECT_EQ((*stats)["watchdog"]["count"].get<size_t>(), 0u);
    }
    const double e_eskf = MaxHorizontalError(out, out.eskf, out.init_time + 20.0, sim.start_time + 100.0);
    const double e_smoother = MaxHorizontalError(out, out.smoother, out.init_time + 20.0, sim.start_time + 100.0);
    std::printf("  max horizontal error: eskf %.3f m, smoother %.3f m\n", e_eskf, e_smoother);
    EXPECT_LT(e_eskf, 0.15);
    EXPECT_LT(e_smoother, 0.15);
  }
}

// A real step of the GNSS positions by 30 m that persists (say, a new reference station) is first
// rejected, then followed: either the run of rejected fixes, all agreeing, is recognised as the estimate
// being off (GateInflation: the gate's doubt doubles every second of the run) and a fix is accepted, or,
// after watchdog.max_reject_s of nothing but rejections, the watchdog re-initialises the estimator from
// GNSS. Either way within max_reject_s (and a fix or two); the estimators follow the new positions from
// then on, and the summary says when and how.
TEST(RobustnessEndToEnd, WatchdogAcceptsAPersistentGnssStep) {
  const SimOptions sim = Shortened(test::TestDrive(3), 125.0);
  const Options options = test::TestRunOptions(sim);
  const double step_t = sim.start_time + 95.0;
  const Vec3 step(30.0, 0.0, 0.0);
  const Output out = RunDrive(sim, options, [&](SimRecord* r) {
    if (r->is<GnssRecord>() && r->get<GnssRecord>().t >= step_t) Displace(sim, step, &r->get<GnssRecord>());
    return true;
  });
  for (const auto& [name, stats, states] :
       {std::tuple{"eskf", &out.eskf_stats, &out.eskf}, std::tuple{"smoother", &out.smoother_stats, &out.smoother}}) {
    SCOPED_TRACE(name);
    const nlohmann::json& w = (*stats)["watchdog"];
    std::printf("%s watchdog %s, gnss %s, re-acquired %s\n", name, w.dump().c_str(),
                (*stats)["gnss_position"].dump().c_str(), (*stats)["gnss_reacquired"].dump().c_str());
    ASSERT_LE(w["count"].get<size_t>(), 1u);
    const std::vector<double> rejected = (*stats)["gnss_position"]["rejected_times"].get<std::vector<double>>();
    ASSERT_FALSE(rejected.empty());
    // Followed from the fix after the last rejection (1 Hz fixes), or from the watchdog's reset.
    double reset_t = rejected.back() + 1.0;
    if (w["count"].get<size_t>() == 1u) {
      reset_t = w["resets"][0]["time"].get<double>();
      EXPECT_EQ(w["resets"][0]["reason"], "gnss_rejected");
      EXPECT_GE(reset_t, step_t + options.watchdog.max_reject);
    } else {
      EXPECT_GE((*stats)["gnss_reacquired"].get<uint64_t>(), 1u);
    }
    // The first fix after the step is rejected, and the step is followed within max_reject_s.
    EXPECT_EQ(rejected.front(), step_t);
    EXPECT_LE(reset_t, step_t + options.watchdog.max_reject + 2.0);
    // Before the step: the true positions; from 5 s after the reset to the GNSS outage: the new ones.
    const double before = MaxHorizontalError(out, *states, out.init_time, step_t - 0.5);
    const double after = MaxHorizontalError(out, *states, reset_t + 5.0, sim.start_time + 125.0, step);
    std::printf("%s: max horizontal error before the step %.4f m, after the reset (vs the new positions) %.4f m\n",
                name, before, after);
    EXPECT_LT(before, 0.15);
    EXPECT_LT(after, 0.3);
    // Every fix after the reset is accepted again.
    for (const auto& t : (*stats)["gnss_position"]["rejected_times"]) EXPECT_LE(t.get<double>(), reset_t);
    EXPECT_GT((*stats)["gnss_position"]["used"].get<uint64_t>(), 70u);
  }
}

// A position σ beyond watchdog.max_position_sigma_m (here 1 m, reached during a 40 s GNSS outage without
// wheels) re-initialises both estimators at the first fix after it, with reason "covariance", once. (The
// smoother watches the σ of the last keyframe it marginalised, so it needs the longer outage.)
TEST(RobustnessEndToEnd, WatchdogResetsWhenThePositionCovarianceExplodes) {
  SimOptions sim = Shortened(test::TestDrive(6), 175.0);
  sim.gnss_outages = {{110.0, 40.0}};
  Options options = test::TestRunOptions(sim);
  options.sensors.wheel.enabled = false;
  options.watchdog.max_position_sigma = 1.0;
  const Output out = RunDrive(sim, options, nullptr);
  const double outage_end = sim.start_time + 150.0;
  for (const auto& [name, stats, states] :
       {std::tuple{"eskf", &out.eskf_stats, &out.eskf}, std::tuple{"smoother", &out.smoother_stats, &out.smoother}}) {
    SCOPED_TRACE(name);
    const nlohmann::json& w = (*stats)["watchdog"];
    std::printf("%s watchdog %s\n", name, w.dump().c_str());
    ASSERT_EQ(w["count"].get<size_t>(), 1u);
    bool found = false;
    for (const auto& r : w["resets"]) {
      EXPECT_EQ(r["reason"], "covariance");
      found |= std::abs(r["time"].get<double>() - outage_end) < 1e-6;
    }
    EXPECT_TRUE(found) << "no reset at the first fix after the outage";
    // Back on track after the reset.
    EXPECT_LT(MaxHorizontalError(out, *states, outage_end + 5.0, sim.start_time + 175.0), 0.3);
  }
}

// A 60 s stop without GNSS (parked in a garage): the standstill updates hold the solution still, with the
// wheel encoders (wheels at zero and IMU quiet) and without them (IMU quiet alone).
TEST(RobustnessEndToEnd, ParkedVehicleDoesNotWanderInEitherEstimator) {
  SimOptions sim = test::TestDrive(4);
  const double d = kDegToRad;
  sim.segments = {
      {20.0, 0.0, 0.0, 0.0},      // standstill (initialisation)
      {10.0, 1.0, 0.0, 0.0},      // to 10 m/s
      {15.0, 0.0, 6.0 * d, 0.0},  // left turn
      {10.0, -1.0, 0.0, 0.0},     // brake to a stop
      {80.0, 0.0, 0.0, 0.0},      // parked
      {10.0, 1.0, 0.0, 0.0},      // drive off
      {10.0, 0.0, 0.0, 0.0},
  };
  // The vehicle stops at about 55.7 s. No GNSS from 57 s to the end of the stop (135 s): the smoother's
  // final output of the first 60 s is written before GNSS returns and the window corrects it.
  const double stop_start = sim.start_time + 55.0;
  sim.gnss_outages = {{57.0, 78.0}};
  for (bool wheels : {true, false}) {
    SCOPED_TRACE(wheels ? "with wheels" : "without wheels");
    Options options = test::TestRunOptions(sim);
    options.sensors.wheel.enabled = wheels;
    const Output out = RunDrive(sim, options, nullptr);
    // Over 60 s of the stop, all without GNSS.
    const double t0 = stop_start + 3.0, t1 = t0 + 60.0;
    for (const auto& [name, states, stats] : {std::tuple{"eskf", &out.eskf, &out.eskf_stats},
                                               std::tuple{"smoother", &out.smoother, &out.smoother_stats}}) {
      const Vec3 drift = PositionAt(*states, t1) - PositionAt(*states, t0);
      double wander = 0.0;  // largest distance from the position at t0 during the stop
      for (const StateEstimate& e : *states) {
        if (e.x.t >= t0 && e.x.t <= t1) wander = std::max(wander, (e.x.p_wb - PositionAt(*states, t0)).norm());
      }
      const double err = MaxHorizontalError(out, *states, t0, t1);
      std::printf("%s wheels=%d (zero-motion factors %s): drift over 60 s parked %.5f m (largest excursion %.5f m), error vs truth %.4f m, "
                  "zero_velocity %s\n",
                  name, wheels, (*stats).value("zero_motion_factors", nlohmann::json(0)).dump().c_str(), drift.norm(), wander, err, (*stats)["zero_velocity"].dump().c_str());
      EXPECT_LT(drift.norm(), 0.005) << name;
      EXPECT_LT(wander, 0.005) << name;
      EXPECT_LT(err, 0.1) << name;
      EXPECT_GT((*stats)["zero_velocity"]["used"].get<uint64_t>(), 50u) << name;
    }
    EXPECT_GT(out.session_stats["standstill_updates"].get<uint64_t>(), 600u);
  }
}

// 1.5 s without IMU records while driving: neither estimator integrates the held sample across the gap;
// both coast, count the gap, and are back on track soon after.
TEST(RobustnessEndToEnd, ImuGapIsCoastedNotIntegratedBlindly) {
  const SimOptions sim = Shortened(test::TestDrive(5), 120.0);
  const Options options = test::TestRunOptions(sim);
  const double gap_start = sim.start_time + 50.0, gap_end = gap_start + 1.5;  // in the left turn
  const Output out = RunDrive(sim, options, [&](SimRecord* r) {
    return !(r->is<ImuSample>() && r->get<ImuSample>().t > gap_start && r->get<ImuSample>().t < gap_end);
  });
  for (const auto& [name, states, stats] : {std::tuple{"eskf", &out.eskf, &out.eskf_stats},
                                             std::tuple{"smoother", &out.smoother, &out.smoother_stats}}) {
    SCOPED_TRACE(name);
    EXPECT_EQ((*stats)["imu_gaps"].get<uint64_t>(), 1u);
    ASSERT_EQ((*stats)["imu_gap_times"].size(), 1u);
    EXPECT_NEAR((*stats)["imu_gap_times"][0][0].get<double>(), gap_start, 1e-6);
    const double near = MaxHorizontalError(out, *states, gap_end, gap_end + 10.0);
    const double later = MaxHorizontalError(out, *states, gap_end + 10.0, sim.start_time + 120.0);
    std::printf("%s: max horizontal error 0-10 s after the gap %.4f m, 10-70 s after %.4f m\n", name, near, later);
    EXPECT_LT(near, 1.0);
    EXPECT_LT(later, 0.15);
  }
}

}  // namespace
}  // namespace gins
