// EstimatorPipeline::SetParallel: every estimator after the first on a thread of its own gives the same streams,
// bit for bit, as the sequential run, and the same statistics.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <vector>

#include "core/sim/simulator.h"
#include "estimators_from_options.h"
#include "sim_feed.h"
#include "solver/eskf.h"
#include "solver/estimator_pipeline.h"
#include "solver/smoother.h"
#include "test_scenarios.h"

namespace gins {
namespace GINS_TEST_FILE {

struct Streams {
  std::vector<StateEstimate> eskf, eskf_rts, smoother, online, batch;
  nlohmann::json stats;
};

Streams RunDrive(bool parallel) {
  SimOptions sim = test::TestDrive(21);
  sim.segments.resize(8);  // 95 s
  const Options options = test::TestRunOptions(sim);
  Streams out;
  EstimatorPipeline session(options.sensors, options.init, options.standstill);
  session.SetParallel(parallel);
  session.AddEstimator(test::MakeEskf(
      options, [&](const StateEstimate& e) { out.eskf.push_back(e); },
      [&](const StateEstimate& e) { out.eskf_rts.push_back(e); }));
  session.AddEstimator(test::MakeSmoother(
      options, [&](const StateEstimate& e) { out.smoother.push_back(e); },
      [&](const StateEstimate& e) { out.online.push_back(e); }, [&](const StateEstimate& e) { out.batch.push_back(e); }));
  Simulator simulator(sim);
  SimRecord rec;
  while (simulator.Next(&rec)) test::FeedSession(&session, rec);
  session.Finish();
  out.stats = session.Stats();
  return out;
}

bool Same(const std::vector<StateEstimate>& a, const std::vector<StateEstimate>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    const NavState &x = a[i].x, &y = b[i].x;
    const bool same = x.t == y.t && x.p_wb == y.p_wb && x.v_w == y.v_w && x.q_wb.coeffs() == y.q_wb.coeffs() &&
                      x.bg == y.bg && x.ba == y.ba && a[i].sigma_p == b[i].sigma_p && a[i].sigma_att == b[i].sigma_att;
    if (!same) return false;
  }
  return true;
}

TEST(SessionParallel, SameStreamsAsTheSequentialRun) {
  const Streams seq = RunDrive(false), par = RunDrive(true);
  ASSERT_GT(seq.eskf.size(), 5000u);
  ASSERT_GT(seq.smoother.size(), 5000u);
  EXPECT_TRUE(Same(seq.eskf, par.eskf));
  EXPECT_TRUE(Same(seq.eskf_rts, par.eskf_rts));
  EXPECT_TRUE(Same(seq.smoother, par.smoother));
  EXPECT_TRUE(Same(seq.online, par.online));
  EXPECT_TRUE(Same(seq.batch, par.batch));
  nlohmann::json a = seq.stats["estimators"], b = par.stats["estimators"];
  for (auto* j : {&a, &b}) {  // timings differ
    (*j)["smoother"].erase("solve_time_s");
    for (const char* k : {"mean_solve_ms", "max_solve_ms", "marginalization_time_s", "mean_marginalization_ms"}) {
      (*j)["smoother"].erase(k);
    }
    (*j)["smoother"]["batch"].erase("solve_time_s");
    (*j)["smoother"]["batch"].erase("covariance_time_s");
    (*j)["eskf"]["rts"].erase("smooth_time_s");
  }
  EXPECT_EQ(a, b);
}

}  // namespace
}  // namespace gins
