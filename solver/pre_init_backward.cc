#include "solver/pre_init_backward.h"

#include <algorithm>
#include <unordered_map>

#include "solver/eskf.h"

namespace gins {
namespace {

// The reversed run's standstill updates come this often (as the pipeline's, EstimatorPipeline::DetectStandstill).
constexpr double kStandstillInterval = 0.1;  // s
// Times closer than this are one epoch.
constexpr double kSameTime = 1e-6;  // s

// A state's velocity and gyro bias negated: the same motion in reversed time (its covariance's v and bg
// blocks' cross terms change sign with them).
NavState Reversed(const NavState& x, double t) {
  NavState r = x;
  r.t = t;
  r.v_w = -x.v_w;
  r.bg = -x.bg;
  return r;
}

Mat15 Reversed(const Mat15& P) {
  Eigen::Matrix<double, 15, 1> sign = Eigen::Matrix<double, 15, 1>::Ones();
  sign.segment<3>(nav::kV).setConstant(-1.0);
  sign.segment<3>(nav::kBg).setConstant(-1.0);
  return sign.asDiagonal() * P * sign.asDiagonal();
}

}  // namespace

std::vector<StateEstimate> FillBackward(const SensorOptions& sensors, const EskfOptions& eskf_options,
                                        const StandstillOptions& standstill, const BackwardSpan& span) {
  const double t_s = span.start.x.t;
  if (span.fixes.empty() || span.imu.empty()) return {};
  // From the first IMU sample (a fix before it would be reached only by coasting).
  const double t_first = std::max(span.from, span.imu.front().t);
  const bool fix_inside = std::any_of(span.fixes.begin(), span.fixes.end(), [&](const GnssMeasurement& f) {
    return f.t >= t_first - kSameTime && f.t < t_s - kSameTime;
  });
  if (!fix_inside) return {};
  const auto reverse = [t_s](double t) { return 2.0 * t_s - t; };

  SensorOptions backward = sensors;
  backward.gnss.estimate_time_offset = false;
  backward.gnss.time_offset = 0.0;
  backward.wheel.enabled = false;
  WatchdogOptions no_watchdog;
  no_watchdog.enabled = false;  // a reset would restart the chain: the span is short and starts known
  std::vector<StateEstimate> smoothed;
  Eskf eskf(backward, eskf_options, standstill, no_watchdog, nullptr,
            [&](const StateEstimate& s) { smoothed.push_back(s); });
  InitResult init;
  init.x0 = Reversed(span.start.x, t_s);
  init.P0 = Reversed(span.P);
  init.earth = span.earth.TimeReversed();
  init.g_norm = span.earth.g_norm();
  eskf.Initialize(init);

  // The span's measurements in reversed time order; at one time the IMU first (as the log is read).
  struct Event {
    double t;
    int kind;  // 0 IMU, 1 fix, 2 standstill
    size_t index;
    double since;
  };
  std::vector<Event> events;
  for (size_t i = 0; i < span.imu.size(); ++i) {
    if (span.imu[i].t < t_s - kSameTime && span.imu[i].t >= t_first - kSameTime) {
      events.push_back({reverse(span.imu[i].t), 0, i, 0.0});
    }
  }
  for (size_t i = 0; i < span.fixes.size(); ++i) {
    const double t = span.fixes[i].t;
    if (t < t_s - kSameTime && t >= t_first - kSameTime) events.push_back({reverse(t), 1, i, 0.0});
  }
  // The standstill updates at IMU samples (after the sample, as the pipeline sends them), about every
  // kStandstillInterval, each standing since the reversed start of its standstill.
  for (const auto& [from, to] : span.rests) {
    const double since = reverse(std::min(to, t_s));
    double last = -1e300;
    for (auto it = span.imu.rbegin(); it != span.imu.rend(); ++it) {
      if (it->t > to || it->t >= t_s - kSameTime) continue;
      if (it->t < std::max(from, t_first) - kSameTime) break;
      const double t = reverse(it->t);
      if (t - since < kStandstillInterval - kSameTime || t - last < kStandstillInterval - kSameTime) continue;
      events.push_back({t, 2, 0, since});
      last = t;
    }
  }
  std::stable_sort(events.begin(), events.end(), [](const Event& x, const Event& y) {
    return x.t < y.t || (x.t == y.t && x.kind < y.kind);
  });
  for (const Event& e : events) {
    if (e.kind == 0) {
      const ImuSample& s = span.imu[e.index];
      eskf.AddImu({e.t, -s.gyro, s.acc});
    } else if (e.kind == 1) {
      GnssMeasurement f = span.fixes[e.index];
      f.t = e.t;
      eskf.Add(f);
    } else {
      StandstillMeasurement m;
      m.t = e.t;
      m.since = e.since;
      eskf.Add(m);
    }
  }
  eskf.Finish();

  // The states' times as the samples had them (2·t_s − t' rounds differently).
  std::unordered_map<double, double> original;
  for (const ImuSample& s : span.imu) original.emplace(reverse(s.t), s.t);
  std::vector<StateEstimate> out;
  for (auto it = smoothed.rbegin(); it != smoothed.rend(); ++it) {
    const auto known = original.find(it->x.t);
    const double t = known != original.end() ? known->second : reverse(it->x.t);
    if (t >= t_s - kSameTime || t < t_first - kSameTime) continue;
    StateEstimate s = *it;
    s.x = Reversed(it->x, t);
    out.push_back(s);
  }
  return out;
}

}  // namespace gins
