// First-estimate Jacobians: a cost function that wraps another so that its Jacobians are
// evaluated at the first estimates of the parameter blocks that have an active one, while its residual is
// always evaluated at the current values. Once a marginalisation prior is built on a block, every other
// factor on it must linearise where the prior did, so that the prior and the factors agree on what is
// observable (no spurious information in yaw or position).
//
// A block's first estimate and its "active" flag are read at each Evaluate, through pointers: the owner
// (the smoother's keyframe) may freeze them between solves, never while Ceres evaluates.
#pragma once

#include <ceres/cost_function.h>

#include <memory>
#include <vector>

#include "factors/pose_manifold.h"

namespace gins {

class FejCost final : public ceres::CostFunction {
 public:
  // Fixed-size scratch in Evaluate: no allocation per evaluation.
  static constexpr int kMaxBlocks = 8;
  static constexpr int kMaxResiduals = 16;

  // How parameter block i is linearised. (Ceres passes its own copies of the parameters to Evaluate, so
  // blocks cannot be recognised by address there.)
  struct Block {
    const double* first_estimate = nullptr;  // null: always linearised at the current value
    const bool* active = nullptr;            // first_estimate is used while *active (null: never)
    bool is_pose = false;                    // a PoseManifold block (7 ambient, 6 tangent)
  };

  // Takes ownership of inner; blocks[i] describes inner's parameter block i.
  FejCost(ceres::CostFunction* inner, std::vector<Block> blocks);
  // Shares inner (the whole-log smoother keeps the window's factors after the window dropped them).
  FejCost(std::shared_ptr<ceres::CostFunction> inner, std::vector<Block> blocks);

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  const ceres::CostFunction& inner() const { return *inner_; }

 private:
  std::shared_ptr<ceres::CostFunction> inner_;
  std::vector<Block> blocks_;
  PoseManifold manifold_;
};

}  // namespace gins
