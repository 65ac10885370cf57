// Tools of the fault-injection tests (tests/solver/fault_injection_test.cc): the log reader's time rules on
// an edited record stream, the truth interpolated at any time, the sanity of every output state, and the
// time an estimator takes to come back within an error bound after a fault.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/geodesy.h"
#include "core/sim/simulator.h"
#include "drive_harness.h"
#include "test_scenarios.h"

namespace gins::test {

inline void SetTime(SimRecord* r, double t) { r->set_t(t); }

// What the log reader (core/io/log_reader.h) lets through of a stream whose time stamps were edited: a record
// older than the newest one is out_of_order, a second record of one type on one stamp a duplicate; both are
// skipped (and counted), the rest passes.
class ReaderRules {
 public:
  bool Accept(const SimRecord& r) {
    const double t = r.t();
    const size_t k = r.type_index();
    if (t < newest_) {
      ++out_of_order;
      return false;
    }
    if (last_[k] == t) {
      ++duplicate;
      return false;
    }
    newest_ = t;
    last_[k] = t;
    return true;
  }
  uint64_t out_of_order = 0, duplicate = 0;

 private:
  double newest_ = -std::numeric_limits<double>::infinity();
  std::array<double, kNumRecordTypes> last_ = [] {
    std::array<double, kNumRecordTypes> none;
    none.fill(-1.0);
    return none;
  }();
};

// The truth position at t, linear between the drive's IMU records (their truth is exact).
inline Vec3 TruthPosition(const DriveRun& run, double t) {
  const auto it = std::lower_bound(run.truth_t.begin(), run.truth_t.end(), t);
  if (it == run.truth_t.begin()) return run.truth.front().p_wb;
  if (it == run.truth_t.end()) return run.truth.back().p_wb;
  const size_t j = static_cast<size_t>(it - run.truth_t.begin());
  const double t0 = run.truth_t[j - 1], t1 = run.truth_t[j];
  const double u = t1 > t0 ? (t - t0) / (t1 - t0) : 0.0;
  return (1.0 - u) * run.truth[j - 1].p_wb + u * run.truth[j].p_wb;
}

// Horizontal error of a state against the truth moved by `offset` (a GNSS jump the estimate should follow).
inline double HorizontalError(const DriveRun& run, const StateEstimate& s, const Vec3& offset = Vec3::Zero()) {
  return (s.x.p_wb - TruthPosition(run, s.x.t) - offset).head<2>().norm();
}

struct WindowError {
  size_t n = 0;
  double max_h = 0.0, rms_h = 0.0;
};

inline WindowError HorizontalErrors(const DriveRun& run, const std::vector<StateEstimate>& states, double from,
                                    double to, const Vec3& offset = Vec3::Zero()) {
  WindowError w;
  double sum = 0.0;
  for (const StateEstimate& s : states) {
    if (s.x.t < from || s.x.t >= to) continue;
    const double e = HorizontalError(run, s, offset);
    w.max_h = std::max(w.max_h, e);
    sum += e * e;
    ++w.n;
  }
  if (w.n > 0) w.rms_h = std::sqrt(sum / static_cast<double>(w.n));
  return w;
}

// Seconds after `from` until the horizontal error stays below `bound` up to `to`: the time of the last state
// in [from, to) at or above the bound, less `from`; 0 when there is none. Infinite without states after
// that (the estimate never came back, or stopped).
inline double RecoveryTime(const DriveRun& run, const std::vector<StateEstimate>& states, double from, double to,
                           double bound, const Vec3& offset = Vec3::Zero()) {
  double last_bad = -1.0, last_good = -1.0;
  for (const StateEstimate& s : states) {
    if (s.x.t < from || s.x.t >= to) continue;
    if (!(HorizontalError(run, s, offset) < bound)) {
      last_bad = s.x.t;
    } else {
      last_good = s.x.t;
    }
  }
  if (last_bad < 0.0) return 0.0;
  return last_good > last_bad ? last_bad - from : std::numeric_limits<double>::infinity();
}

// Every output state of every stream: finite, a unit quaternion, σ finite and > 0 where the stream writes
// them (the ESKF, the smoother's final states; the online stream writes none), time non-decreasing.
inline void ExpectSaneOutputs(const DriveRun& run) {
  const struct {
    const char* name;
    const std::vector<StateEstimate>* states;
    bool sigma_written;
  } streams[] = {{"eskf", &run.eskf, true}, {"smoother", &run.smoother, true},
                 {"smoother_online", &run.smoother_online, false}};
  for (const auto& s : streams) {
    double last_t = -1e300;
    size_t bad = 0;
    for (const StateEstimate& e : *s.states) {
      const Eigen::Matrix<double, 9, 1> sigma = (Eigen::Matrix<double, 9, 1>() << e.sigma_p, e.sigma_v, e.sigma_att).finished();
      const bool ok = e.x.AllFinite() && sigma.allFinite() && std::abs(e.x.q_wb.norm() - 1.0) < 1e-6 &&
                      (s.sigma_written ? sigma.minCoeff() > 0.0 : sigma.minCoeff() >= 0.0) && e.x.t >= last_t;
      if (!ok && bad++ == 0) {
        ADD_FAILURE() << s.name << ": bad state at t=" << std::fixed << e.x.t << " (previous t " << last_t
                      << "): p " << e.x.p_wb.transpose() << ", σ " << sigma.transpose();
      }
      last_t = std::max(last_t, e.x.t);
    }
    EXPECT_EQ(bad, 0u) << s.name << ": states that are not finite, lack σ or go back in time";
  }
}

// The drive cut after `duration` seconds (keeps the tests cheap, also under the sanitizers).
inline SimOptions Shortened(SimOptions sim, double duration) {
  std::vector<SimSegment> kept;
  double t = 0.0;
  for (SimSegment seg : sim.segments) {
    if (t >= duration) break;
    seg.duration = std::min(seg.duration, duration - t);
    t += seg.duration;
    kept.push_back(seg);
  }
  sim.segments = kept;
  return sim;
}

// Moves a fix by `d` (ENU metres) in the simulation's world frame.
inline void Displace(const SimOptions& sim, const Vec3& d, GnssRecord* g) {
  const LocalEnuFrame frame(sim.origin);
  const GeodeticPoint q = frame.ToGeodetic(frame.ToEnu({g->lat_deg, g->lon_deg, g->alt_m}) + d);
  g->lat_deg = q.lat_deg;
  g->lon_deg = q.lon_deg;
  g->alt_m = q.alt_m;
}

// The figures the fault table of docs/robustness.md quotes, in one greppable line per estimator.
inline void PrintRecovery(const std::string& fault, const char* estimator, double recovery_s, double max_h_during,
                          double max_h_after) {
  std::printf("[fault] %-44s %-8s recovery %6.2f s, max horizontal error during %8.3f m, after %6.3f m\n",
              fault.c_str(), estimator, recovery_s, max_h_during, max_h_after);
}

// What an estimator counted (for a failed recovery): GNSS rejections, watchdog resets, IMU gaps.
inline std::string EstimatorCounts(const DriveRun& run, const std::string& estimator) {
  const nlohmann::json& j = run.stats["estimators"][estimator];
  return "gnss_position " + j["gnss_position"].dump() + ", watchdog " + j["watchdog"].dump() + ", imu_gaps " +
         j["imu_gaps"].dump();
}

// "Back" after a fault: the horizontal error of a healthy estimate on these drives (RTK-like fixes, σ 2 cm
// horizontal, at 1 Hz, with a dual-antenna heading: a few centimetres) with margin.
constexpr double kFaultBound = 0.2;  // m

// The drive of test_scenarios.h cut to `duration` seconds, without its GNSS outage unless kept.
inline SimOptions FaultDrive(unsigned seed, double duration, bool keep_outage = false) {
  SimOptions sim = Shortened(TestDrive(seed), duration);
  if (!keep_outage) sim.gnss_outages.clear();
  return sim;
}

// A hook that drops the records for which `drop(record)` is true.
inline RecordHook Dropping(std::function<bool(const SimRecord&)> drop) {
  return [drop](const SimRecord& r, const std::function<void(const SimRecord&)>& feed, EstimatorPipeline&) {
    if (!drop(r)) feed(r);
  };
}

// A hook that edits the records, or drops them (edit returns false).
inline RecordHook Editing(std::function<bool(SimRecord*)> edit) {
  return [edit](const SimRecord& r, const std::function<void(const SimRecord&)>& feed, EstimatorPipeline&) {
    SimRecord e = r;
    if (edit(&e)) feed(e);
  };
}

// For each estimator run: the recovery after the fault [fault_start, fault_end) is at most `max_recovery`
// seconds (horizontal error below `bound` from then to `to`, against the truth moved by `offset`); prints the
// figures.
inline void ExpectRecovery(const std::string& fault, const DriveRun& run, double fault_start, double fault_end,
                           double to, double max_recovery, double bound = kFaultBound,
                           const Vec3& offset = Vec3::Zero(), bool with_smoother = true) {
  for (const auto& [name, states] : {std::pair{"eskf", &run.eskf}, std::pair{"smoother", &run.smoother}}) {
    if (!with_smoother && states == &run.smoother) continue;
    SCOPED_TRACE(std::string(name) + ": " + fault);
    const double recovery = RecoveryTime(run, *states, fault_end, to, bound, offset);
    const WindowError during = HorizontalErrors(run, *states, fault_start, fault_end + recovery, offset);
    const WindowError after = HorizontalErrors(run, *states, fault_end + recovery + 1e-6, to, offset);
    PrintRecovery(fault, name, recovery, during.max_h, after.max_h);
    EXPECT_LE(recovery, max_recovery) << EstimatorCounts(run, name);
    EXPECT_GT(after.n, 0u) << "no states after the recovery";
  }
}

}  // namespace gins::test
