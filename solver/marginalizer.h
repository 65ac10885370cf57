// Marginalisation of blocks out of the smoother's problem: the Schur complement of every
// residual that touches them (factors/marginalization_prior.h) becomes a prior on the blocks those residuals
// also touch; then the residuals, the blocks and the prior change places in the problem.
//
// Determinism: the residuals are selected, Schur-complemented and removed in the problem's own (insertion)
// order, and the blocks removed in the order given; Ceres's own lists follow hashes of addresses, so the
// last bits of every later estimate would follow the heap's layout.
#pragma once

#include <ceres/problem.h>

#include <memory>
#include <vector>

#include "factors/marginalization_prior.h"

namespace gins {

class Marginalizer {
 public:
  // Selects the residuals of `problem` that touch marg_blocks and Schur-complements them out at the
  // blocks' current values. The problem is not changed until Apply. Blocks held constant in the problem
  // stay fixed (no column in the prior); a block with a manifold is taken for a pose block.
  Marginalizer(ceres::Problem* problem, std::vector<double*> marg_blocks);

  // The residuals touching the marginalised blocks, in program order.
  const std::vector<ceres::ResidualBlockId>& residuals() const { return residuals_; }
  // Whether the Schur complement succeeded (else Apply adds no prior).
  bool ok() const { return ok_; }
  const MarginalizationInfo& info() const { return info_; }
  // The prior Apply will add (linearised at the blocks' values at construction); null if none.
  const MarginalizationPrior* prior() const { return prior_.get(); }

  // Removes the residuals (program order), then the marginalised blocks (in the given order), then adds
  // the prior on the kept blocks. Returns the prior's id, null when there is none. Once only.
  ceres::ResidualBlockId Apply();

 private:
  void Declare(double* block);

  ceres::Problem* problem_;
  std::vector<double*> marg_blocks_;
  std::vector<ceres::ResidualBlockId> residuals_;
  std::vector<double*> declared_;
  MarginalizationInfo info_;
  std::unique_ptr<MarginalizationPrior> prior_;  // null when nothing is kept or no information remains
  bool ok_ = false;
  bool applied_ = false;
};

}  // namespace gins
