// One decoded stream (stream_format.h) through a EstimatorPipeline with both estimators, fed as `gins run` feeds a log
// (and given up like it when initialisation takes longer than init.max_wait_s), and the estimators' promises
// checked whatever the input:
//   - nothing aborts or throws, except RunError from Finish when the run never initialised, and RunError from
//     a record the sanity checks refuse (core/imu_checks.h: wrong IMU units or axes), which ends the run as
//     `gins run` ends it, writing nothing;
//   - every state and σ of every output stream is finite, the quaternion a unit one;
//   - σ > 0 on the streams that write their σ (the ESKF, the smoother's final states); σ ≥ 0 on the
//     smoother's online stream, which writes none (zero: not computed);
//   - each stream's times are non-decreasing and within the times of the records fed;
//   - the summary's statistics serialise.
// The run's end is the fuzzer's timeout. Used by the fuzzer and by the corpus replay test.
#pragma once

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "estimators_from_options.h"
#include "fuzz/stream_format.h"
#include "solver/eskf.h"
#include "solver/estimator_pipeline.h"
#include "solver/smoother.h"

namespace gins::fuzz {

// The first violation of one output stream, kept in *failure (left alone once set).
class StreamChecker {
 public:
  StreamChecker(const char* name, bool sigma_written, const double* first_t, const double* newest_t,
                std::string* failure)
      : name_(name), sigma_written_(sigma_written), first_t_(first_t), newest_t_(newest_t), failure_(failure) {}

  void operator()(const StateEstimate& e) {
    if (!failure_->empty()) return;
    const double t = e.x.t;
    const bool finite = e.x.AllFinite() && e.sigma_p.allFinite() && e.sigma_v.allFinite() &&
                        e.sigma_att.allFinite() && std::isfinite(e.odom_scale);
    const Eigen::Matrix<double, 9, 1> sigmas = (Eigen::Matrix<double, 9, 1>() << e.sigma_p, e.sigma_v, e.sigma_att).finished();
    if (!finite) {
      Fail("a state or σ is not finite", e);
    } else if (std::abs(e.x.q_wb.norm() - 1.0) > 1e-3) {
      Fail("the attitude quaternion is not a unit one", e);
    } else if (sigma_written_ ? !(sigmas.minCoeff() > 0.0) : !(sigmas.minCoeff() >= 0.0)) {
      Fail(sigma_written_ ? "a written σ is not > 0" : "a σ is negative", e);
    } else if (t < last_t_) {
      Fail(("time went back from " + std::to_string(last_t_)).c_str(), e);
    } else if (t < *first_t_ - 1e-6 || t > *newest_t_ + 1e-6) {
      Fail("time outside the records fed", e);
    }
    last_t_ = t;
  }

 private:
  void Fail(const char* what, const StateEstimate& e) {
    char buf[400];
    std::snprintf(buf, sizeof(buf),
                  "%s: %s at t=%.9f (p %g %g %g, v %g %g %g, q %g %g %g %g, σp %g %g %g, σv %g %g %g, σatt %g %g %g)",
                  name_, what, e.x.t, e.x.p_wb.x(), e.x.p_wb.y(), e.x.p_wb.z(), e.x.v_w.x(), e.x.v_w.y(), e.x.v_w.z(),
                  e.x.q_wb.w(), e.x.q_wb.x(), e.x.q_wb.y(), e.x.q_wb.z(), e.sigma_p.x(), e.sigma_p.y(), e.sigma_p.z(),
                  e.sigma_v.x(), e.sigma_v.y(), e.sigma_v.z(), e.sigma_att.x(), e.sigma_att.y(), e.sigma_att.z());
    *failure_ = buf;
  }

  const char* name_;
  bool sigma_written_;
  const double* first_t_;
  const double* newest_t_;
  std::string* failure_;
  double last_t_ = -1e300;
};

struct StreamResult {
  std::string failure;  // empty: every invariant held
  size_t records = 0;
  bool initialized = false;
  size_t states = 0;    // over all output streams
  std::string refused;  // the sanity checks' reason when they refused the input (not a failure)
};

inline StreamResult RunStream(const uint8_t* data, size_t size) {
  StreamResult result;
  StreamDecoder decoder(data, size);
  const Options options = decoder.options();
  double first_t = -1.0, newest_t = 0.0;
  StreamChecker eskf("eskf", true, &first_t, &newest_t, &result.failure);
  StreamChecker final_states("smoother", true, &first_t, &newest_t, &result.failure);
  StreamChecker online("smoother_online", false, &first_t, &newest_t, &result.failure);
  auto counted = [&result](StreamChecker* c) {
    return [&result, c](const StateEstimate& e) {
      ++result.states;
      (*c)(e);
    };
  };
  EstimatorPipeline session(options.sensors, options.init, options.standstill);
  session.AddEstimator(test::MakeEskf(options, counted(&eskf)));
  session.AddEstimator(test::MakeSmoother(options, counted(&final_states), counted(&online)));
  LogRecord r;
  while (decoder.Next(&r)) {
    if (first_t < 0.0) first_t = r.t();
    newest_t = r.t();
    ++result.records;
    try {
      session.Add(r);
    } catch (const RunError& e) {
      result.refused = e.what();  // the sanity checks: gins run stops here, with the reason
      return result;
    }
    // gins run gives up here (RunError) and writes nothing.
    if (!session.initialized() && session.elapsed() > options.init.max_wait) return result;
  }
  result.initialized = session.initialized();
  try {
    session.Finish();
    if (!result.initialized && result.failure.empty()) result.failure = "Finish did not throw without initialisation";
  } catch (const RunError&) {
    if (result.initialized && result.failure.empty()) result.failure = "RunError from an initialised session";
  }
  const std::string stats = session.Stats().dump();
  if (stats.empty() && result.failure.empty()) result.failure = "empty statistics";
  return result;
}

}  // namespace gins::fuzz
