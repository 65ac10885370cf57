#include "solver/marginalizer.h"

#include <glog/logging.h>

#include <algorithm>
#include <utility>

namespace gins {

Marginalizer::Marginalizer(ceres::Problem* problem, std::vector<double*> marg_blocks)
    : problem_(problem), marg_blocks_(std::move(marg_blocks)) {
  // In the problem's own (insertion) order, not GetResidualBlocksForParameterBlock's, which follows a hash
  // of addresses: the sums of the Schur complement, and so the last bits of every later estimate, would
  // then change from run to run with the heap's layout.
  std::vector<ceres::ResidualBlockId> all_ids;
  problem_->GetResidualBlocks(&all_ids);
  for (auto id : all_ids) {
    std::vector<double*> params;
    problem_->GetParameterBlocksForResidualBlock(id, &params);
    const bool touches = std::any_of(params.begin(), params.end(), [&](double* b) {
      return std::find(marg_blocks_.begin(), marg_blocks_.end(), b) != marg_blocks_.end();
    });
    if (touches) residuals_.push_back(id);
  }
  for (auto id : residuals_) {
    std::vector<double*> params;
    problem_->GetParameterBlocksForResidualBlock(id, &params);
    for (double* b : params) Declare(b);
    info_.AddResidualBlock(problem_->GetCostFunctionForResidualBlock(id), problem_->GetLossFunctionForResidualBlock(id),
                           params);
  }
  ok_ = info_.Marginalize();
  if (ok_) prior_ = info_.CreatePrior();
}

void Marginalizer::Declare(double* b) {
  if (std::find(declared_.begin(), declared_.end(), b) != declared_.end()) return;
  declared_.push_back(b);
  const bool is_marg = std::find(marg_blocks_.begin(), marg_blocks_.end(), b) != marg_blocks_.end();
  const bool is_const = problem_->IsParameterBlockConstant(b);
  const MarginalizationInfo::Role role = is_const  ? MarginalizationInfo::Role::kConstant
                                         : is_marg ? MarginalizationInfo::Role::kMarginalize
                                                   : MarginalizationInfo::Role::kKeep;
  const BlockKind kind = problem_->GetManifold(b) != nullptr ? BlockKind::kPose : BlockKind::kEuclidean;
  info_.AddParameterBlock(b, kind, problem_->ParameterBlockSize(b), role);
}

ceres::ResidualBlockId Marginalizer::Apply() {
  CHECK(!applied_) << "Marginalizer::Apply twice";
  applied_ = true;
  // Residuals first, in program order: RemoveParameterBlock would remove them in the order of a hash set of
  // addresses, and each removal moves the problem's last residual into the hole, so the residual order (and
  // the last bits of every later solve) would follow the heap's layout.
  for (auto id : residuals_) problem_->RemoveResidualBlock(id);
  for (double* b : marg_blocks_) problem_->RemoveParameterBlock(b);
  if (!prior_) return nullptr;
  return problem_->AddResidualBlock(prior_.release(), nullptr, info_.kept_parameter_blocks());
}

}  // namespace gins
