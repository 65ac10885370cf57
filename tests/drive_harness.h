// End-to-end harness for the seeded drive tests: a simulated drive through one EstimatorPipeline with both
// estimators (records may be edited or added on the way), and the accuracy of each output stream against
// the simulator's truth over a time range.
#pragma once

#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/options.h"
#include "core/sim/simulator.h"
#include "core/so3.h"
#include "estimators_from_options.h"
#include "sim_feed.h"
#include "solver/eskf.h"
#include "solver/estimator_pipeline.h"
#include "solver/smoother.h"

namespace gins::test {

struct DriveRun {
  std::vector<double> truth_t;  // the truth at every IMU record
  std::vector<NavState> truth;
  std::vector<StateEstimate> eskf, smoother, smoother_online;
  std::vector<StateEstimate> eskf_rts, batch;  // with smoothing: the two-sided streams
  bool initialized = false;
  double first_t = 0.0, init_t = 0.0;
  nlohmann::json stats;  // EstimatorPipeline::Stats()
};

// Called for every simulated record before the session sees it; feed(rec) passes a record on (call it
// zero, one or more times, e.g. to drop, edit or add records); the session is there for records the
// simulator does not make.
using RecordHook = std::function<void(const SimRecord& rec, const std::function<void(const SimRecord&)>& feed,
                                      EstimatorPipeline& session)>;

inline DriveRun RunDriveThroughSession(const SimOptions& sim, const Options& options,
                                       const RecordHook& hook = nullptr, bool with_eskf = true,
                                       bool with_smoother = true, bool with_smoothing = false) {
  DriveRun out;
  Simulator simulator(sim);
  EstimatorPipeline session(options.sensors, options.init, options.standstill);
  if (with_eskf) {
    StateCallback rts;
    if (with_smoothing) rts = [&](const StateEstimate& e) { out.eskf_rts.push_back(e); };
    session.AddEstimator(
        test::MakeEskf(options, [&](const StateEstimate& e) { out.eskf.push_back(e); }, std::move(rts)));
  }
  if (with_smoother) {
    StateCallback batch;
    if (with_smoothing) batch = [&](const StateEstimate& e) { out.batch.push_back(e); };
    session.AddEstimator(test::MakeSmoother(
        options, [&](const StateEstimate& e) { out.smoother.push_back(e); },
        [&](const StateEstimate& e) { out.smoother_online.push_back(e); }, std::move(batch)));
  }
  const std::function<void(const SimRecord&)> feed = [&](const SimRecord& r) { FeedSession(&session, r); };
  SimRecord rec;
  bool first = true;
  while (simulator.Next(&rec)) {
    if (first) out.first_t = rec.t();
    first = false;
    if (rec.is<ImuSample>()) {
      out.truth_t.push_back(rec.get<ImuSample>().t);
      out.truth.push_back(rec.truth);
    }
    if (hook) {
      hook(rec, feed, session);
    } else {
      feed(rec);
    }
  }
  out.initialized = session.initialized();
  if (out.initialized) {
    session.Finish();
    out.init_t = session.init_result().x0.t;
  }
  out.stats = session.Stats();
  return out;
}

struct DriveErrors {
  size_t n = 0;
  double rmse_h = 0.0, max_h = 0.0, rmse_v = 0.0, rmse_vel = 0.0, rmse_yaw_deg = 0.0, max_yaw_deg = 0.0;
};

// Calls f(state, j) for each state with t in [from, to) and run.truth[j] the truth at the same IMU time
// (states at other times, e.g. keyframes between IMU samples, are skipped). States in time order.
template <typename F>
void ForEachAtTruth(const DriveRun& run, const std::vector<StateEstimate>& states, double from, double to, F f) {
  size_t j = 0;
  for (const StateEstimate& s : states) {
    const double t = s.x.t;
    if (t < from || t >= to) continue;
    while (j < run.truth_t.size() && run.truth_t[j] < t - 1e-7) ++j;
    if (j == run.truth_t.size() || std::abs(run.truth_t[j] - t) > 1e-7) continue;
    f(s, j);
  }
}

// Share of the IMU epochs from `from` on at which a stream has a state.
inline double Coverage(const DriveRun& run, const std::vector<StateEstimate>& states, double from) {
  size_t epochs = 0, covered = 0;
  for (double t : run.truth_t) epochs += t >= from;
  ForEachAtTruth(run, states, from, 1e300, [&](const StateEstimate&, size_t) { ++covered; });
  return epochs > 0 ? static_cast<double>(covered) / static_cast<double>(epochs) : 0.0;
}

// Errors of the states with t in [from, to) against the truth at the same IMU time.
inline DriveErrors Errors(const DriveRun& run, const std::vector<StateEstimate>& states, double from,
                          double to = 1e300) {
  DriveErrors e;
  double h2 = 0.0, v2 = 0.0, vel2 = 0.0, yaw2 = 0.0;
  ForEachAtTruth(run, states, from, to, [&](const StateEstimate& s, size_t j) {
    const NavState& x = run.truth[j];
    const Vec3 d = s.x.p_wb - x.p_wb;
    const double yaw = WrapAngle(YawOfXAxis<double>(s.x.R_wb()) - YawOfXAxis<double>(x.R_wb())) * kRadToDeg;
    h2 += d.head<2>().squaredNorm();
    v2 += d.z() * d.z();
    vel2 += (s.x.v_w - x.v_w).squaredNorm();
    yaw2 += yaw * yaw;
    e.max_h = std::max(e.max_h, d.head<2>().norm());
    e.max_yaw_deg = std::max(e.max_yaw_deg, std::abs(yaw));
    ++e.n;
  });
  if (e.n > 0) {
    const double n = static_cast<double>(e.n);
    e.rmse_h = std::sqrt(h2 / n);
    e.rmse_v = std::sqrt(v2 / n);
    e.rmse_vel = std::sqrt(vel2 / n);
    e.rmse_yaw_deg = std::sqrt(yaw2 / n);
  }
  return e;
}

inline void PrintErrors(const char* what, const DriveErrors& e) {
  std::printf("[ %-28s] %zu states: rmse_h %.3f m (max %.3f), rmse_v %.3f m, vel %.4f m/s, yaw %.3f deg (max %.3f)\n",
              what, e.n, e.rmse_h, e.max_h, e.rmse_v, e.rmse_vel, e.rmse_yaw_deg, e.max_yaw_deg);
}

}  // namespace gins::test
