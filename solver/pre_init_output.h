// What an estimator writes for the time before its initialisation (core/initializer.h), so that every output
// starts at the first fix (docs/estimators.md, "Initialisation"):
//   forward streams   the states at rest of the first standstill as they come (Initializer::RestStates: the
//                     standstill's position, a zero velocity, an unknown yaw); then, at the initialisation,
//                     what the vehicle did after them (it moved, maybe stood again) up to the fit's window,
//                     run backwards from the fit's first state (solver/pre_init_backward.h), and the fit's
//                     window bridged through its IMU samples from the fit's first state to its last
//                     (solver/imu_bridge.h), where the estimator's own stream begins: these used only data
//                     up to there, so they are causal, only late.
//   two-sided streams (ESKF + RTS, batch) end knowing the yaw: in front of their first state (at the
//                     initialisation) the backward run from that state, from the first fix on: the
//                     standstills with the yaw found later, the motion between them, the fit's window.
// The backward runs need a filler (SetBackwardFiller, the estimator's FillBackward); without one the
// forward streams have the first standstill and the fit's window, the two-sided ones nothing in front.
#pragma once

#include <functional>
#include <utility>
#include <vector>

#include "core/initializer.h"
#include "solver/estimator.h"
#include "solver/imu_bridge.h"
#include "solver/keyframe.h"
#include "solver/pre_init_backward.h"

namespace gins {

class PreInitOutput {
 public:
  using BackwardFiller = std::function<std::vector<StateEstimate>(const BackwardSpan&)>;
  explicit PreInitOutput(const BridgeNoise& noise) : noise_(noise) {}
  // What runs backwards from a known state (FillBackward with the estimator's options).
  void SetBackwardFiller(BackwardFiller filler) { backward_ = std::move(filler); }

  // A rest state: written to the forward streams (either may be empty) while the first standstill lasts
  // (a run of rest states, none kBreak apart); kept for the backward runs and the two-sided streams.
  void Add(const StateEstimate& s, const StateCallback& forward, const StateCallback& forward2 = nullptr);
  // The first initialisation (later ones, the watchdog's, change nothing): to the forward streams, the
  // states after the last rest state written and before init.x0.t, where the estimator's own first state
  // goes (the backward run to the fit's start, then the fit's window bridged).
  void Start(const InitResult& init, const StateCallback& forward, const StateCallback& forward2 = nullptr);
  // `out` with the backward run from its first state (at the initialisation) in front of it.
  StateCallback TwoSided(const StateCallback& out) const;

  // Rest states further apart than this belong to different standstills.
  static constexpr double kBreak = 0.5;  // s

 private:
  // The backward run's measurements in [from, to) (its start and covariance left to the caller).
  BackwardSpan Span(double from, double to) const;
  BridgeNoise noise_;
  std::vector<double> rest_times_;  // every rest state's
  double last_forward_t_ = -1e300;
  bool first_standstill_over_ = false;
  bool started_ = false;
  NavState fit_start_, fit_end_;
  EarthModel earth_;
  std::vector<HeldImuSample> steps_;  // the fit's window, from fit_start_.t to fit_end_.t
  BackwardFiller backward_;
  // With a filler: the fit's end covariance, and what came before the initialisation (InitResult::pre_init_*).
  Mat15 P0_ = Mat15::Identity();
  std::vector<ImuSample> pre_init_imu_;
  std::vector<GnssMeasurement> pre_init_fixes_;
};

}  // namespace gins
