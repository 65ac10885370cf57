// What an estimator writes for the time before its initialisation (core/initializer.h), so that every output
// starts at the first fix (docs/estimators.md, "Initialisation"):
//   forward streams   the states at rest as they come (Initializer::RestStates: the standstill's position, a
//                     zero velocity, an unknown yaw); then, at the initialisation, the fit's window bridged
//                     through its IMU samples from the fit's first state to its last (solver/imu_bridge.h),
//                     where the estimator's own stream begins: the fit used only data up to there, so
//                     these states are causal, only late by the window's length.
//   two-sided streams (ESKF + RTS, batch) end knowing the yaw: in front of their first state (at the
//                     initialisation) they write the rest epochs of the standstill the fit started from and
//                     the fit's window, from that first state carried back through the fit's motion (its
//                     rotation and displacement, turned by the two-sided pass's correction of the fit's
//                     attitude) and bridged to it. Rest epochs of an earlier standstill (the vehicle may have
//                     turned since) are not written there.
#pragma once

#include <vector>

#include "core/initializer.h"
#include "solver/estimator.h"
#include "solver/imu_bridge.h"
#include "solver/keyframe.h"

namespace gins {

class PreInitOutput {
 public:
  explicit PreInitOutput(const BridgeNoise& noise) : noise_(noise) {}

  // A rest state: written to the forward streams (either may be empty); kept for the two-sided ones when
  // keep.
  void Add(const StateEstimate& s, bool keep, const StateCallback& forward, const StateCallback& forward2 = nullptr);
  // The first initialisation (later ones, the watchdog's, change nothing): the fit's window, bridged, to the forward streams (the states after the last rest
  // state written and before init.x0.t, where the estimator's own first state goes).
  void Start(const InitResult& init, const StateCallback& forward, const StateCallback& forward2 = nullptr);
  // `out` with the kept rest epochs and the fit's window in front of its first state.
  StateCallback TwoSided(const StateCallback& out) const;

  // `first` (a two-sided state at the end of the fit) carried back to the fit's start: the fit's rotation
  // and displacement from fit_start to fit_end, turned by first's attitude correction of fit_end; its σ.
  static StateEstimate Carried(const StateEstimate& first, const NavState& fit_start, const NavState& fit_end);

 private:
  struct Epoch {
    double t;
    Vec3 sigma_v;
  };
  BridgeNoise noise_;
  std::vector<Epoch> kept_;
  double last_forward_t_ = -1e300;
  bool started_ = false;
  bool from_standstill_ = false;
  double static_start_ = 0.0;
  NavState fit_start_, fit_end_;
  EarthModel earth_;
  std::vector<HeldImuSample> steps_;  // the fit's window, from fit_start_.t to fit_end_.t
};

}  // namespace gins
