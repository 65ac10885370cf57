// A measurement module's factors (core/measurement_module.h): its model, a function of the kinematic state at
// the measurement's time (PredictedKinematics: p, v, q), with autodiff Jacobians.
//   at a keyframe's time         ModuleFactorAtKeyframe: the keyframe's pose (7) and velocity (3)
//   through the IMU from one     ModuleFactorPreint: PreintAttachedFactor<Model> on pose_i (7), vel_i (3),
//                                bias_i (6) (factors/preint_attached_factor.h)
// Residual: the model's, whitened by it (kResidualDim rows). Only the translation units that attach modules'
// measurements include this header (solver/smoother_attachers.cc): the autodiff is compiled there once per
// module.
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <memory>
#include <utility>

#include "factors/preint_attached_factor.h"
#include "factors/raw_gnss_factor.h"

namespace gins {

template <class Model>
ceres::CostFunction* ModuleFactorAtKeyframe(const Model& model) {
  return new ceres::AutoDiffCostFunction<RawAtKeyframeFactor<Model>, Model::kResidualDim, pose::kAmbient, 3>(
      new RawAtKeyframeFactor<Model>(model));
}

template <class Model>
ceres::CostFunction* ModuleFactorPreint(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth,
                                        const Model& model) {
  return new ceres::AutoDiffCostFunction<PreintAttachedFactor<Model>, Model::kResidualDim, pose::kAmbient, 3, 6>(
      new PreintAttachedFactor<Model>(std::move(preint), earth, model));
}

}  // namespace gins
