// What the smoother's window predicts for a new measurement, and the check of a factor against it before it
// is attached: the same innovation test the ESKF makes, S = HPHᵀ + R, with P the predicted state's marginal
// covariance from the whole window (not R alone: after an outage the window itself is uncertain, and a
// check that ignored that rejected every returning fix).
//
// Covariances here are over keyframe blocks' tangents in table order (pose 6, velocity 3, bias 6, scale 1
// when estimated: KeyframeStore::EstimatedTypes), keyframe after keyframe for a joint one.
#pragma once

#include <ceres/cost_function.h>

#include <vector>

#include "core/preintegration.h"
#include "solver/estimator_options.h"
#include "solver/keyframe.h"

namespace gins {

// The covariance of the state at the end of `pre` (from keyframe state x_i with block-order covariance
// cov_i): the preintegrated transition, the IMU noise over it and the random walks of biases, scale and time offset.
// joint (optional): the covariance of both, i's blocks then the predicted ones.
MatX PredictBlockCovariance(const std::vector<BlockType>& types, const MatX& cov_i, const NavState& x_i,
                            const Preintegration& pre, const SensorOptions& options, MatX* joint = nullptr);

// The covariance restricted to some of a keyframe's blocks (their tangents, in the order listed).
MatX SubCovariance(const std::vector<BlockType>& types, const MatX& cov, const std::vector<BlockType>& wanted,
                   int keyframe = 0);

// A factor checked against a prediction: its whitened residual r and tangent Jacobian J at the blocks'
// current values, and Σ the joint covariance of those blocks' tangents (in the factor's parameter order):
// S = J·Σ·Jᵀ + I, χ² = rᵀ·S⁻¹·r.
struct FactorCheck {
  bool evaluated = false;  // false: not finite, or S not positive definite
  double chi2 = 0.0;
  VecX residual;           // whitened
  MatX S;                  // whitened innovation covariance
  bool Passes(double gate) const { return evaluated && chi2 <= gate; }
};
// posterior: Σ is of a solution the factor is part of, so the residual's covariance is I − J·Σ·Jᵀ (the
// post-fit check of a used measurement) instead of I + J·Σ·Jᵀ.
FactorCheck CheckFactor(const ceres::CostFunction& cost, const std::vector<const double*>& params,
                        const std::vector<BlockKind>& kinds, const MatX& sigma, bool posterior = false);

}  // namespace gins
