// IMU-rate states between two smoothed states (two keyframes of the batch, two measurement epochs of the
// RTS pass, two keyframes leaving the window): propagated from the first through the IMU steps between
// them, then pulled onto the second, so that the stream meets both without a jump. The mismatch
// e = x_b ⊟ x̂(t_b) at the second (position, velocity, world-frame attitude, biases) is spread linearly in
// time: x(t) = x̂(t) ⊞ s·e, s = (t - t_a) / (t_b - t_a); the error of a strapdown propagation grows smoothly
// between two fixed ends, so a linear share is its first-order bridge.
//
// 1-σ: the variances of the ends interpolated linearly, plus the bridge's own s(1-s)·Q, Q the IMU white
// noise over the interval (a Brownian bridge: largest mid-way, zero at the ends). Each end keeps its σ.
#pragma once

#include <vector>

#include "core/preintegration.h"
#include "solver/estimator.h"
#include "solver/keyframe.h"

namespace gins {

struct BridgeNoise {
  double gyro_noise_density = 0.0;  // rad/s/√Hz
  double acc_noise_density = 0.0;   // m/s²/√Hz
};

// Emits a, then the states at the end of each step in `steps` (which start at a.x.t), except the last one
// when b is given (b emits itself). Without b, the states are propagated from a alone (a stream's tail).
// standing: the vehicle stood from a to b (zero velocity, no IMU wobble).
void EmitBridge(const StateEstimate& a, const StateEstimate* b, const std::vector<HeldImuSample>& steps,
                const ImuEarthTerms& earth, const BridgeNoise& noise, bool standing, const StateCallback& out);

}  // namespace gins
