// Marginalisation: the Schur complement of the residuals that touch the blocks being dropped from the
// window (MarginalizationInfo), and the prior factor it leaves on the blocks that stay
// (MarginalizationPrior). Independent of the smoother's bookkeeping: blocks are plain pointers + kind.
//
// Prior residual (m rows, m ≤ n = Σ tangent sizes of the kept blocks):
//   r(x) = r0 + J·(x ⊟ x0),   x ⊟ x0 = [Minus(x_1, x0_1); ...; Minus(x_K, x0_K)]
// with Minus the block's manifold Minus (pose: PoseManifold, right-perturbed; Euclidean: subtraction) and
// x0 the linearisation point copied at marginalisation time. Its Jacobian w.r.t. the ambient block k is
// J_k·∂Minus(x_k, x0_k)/∂x_k evaluated at the current x_k, so that, after Ceres multiplies by the block's
// PlusJacobian, the tangent Jacobian is exactly J_k at x0 and follows the chain rule (Jr⁻¹ of the rotation
// difference) away from it. ½|r|² = ½δᵀ(JᵀJ)δ + δᵀ(Jᵀr0) + const reproduces the marginal information
// H* = JᵀJ and gradient b* = Jᵀr0 (up to the dropped null space).
#pragma once

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <memory>
#include <vector>

#include "core/conventions.h"

namespace gins {

// How a parameter block is perturbed. Pose: 7 ambient / 6 tangent (factors/pose_manifold.h); Euclidean:
// ambient = tangent = its size.
enum class BlockKind { kEuclidean, kPose };

int TangentSizeOf(BlockKind kind, int ambient_size);

// One block of a prior: its kind, sizes and linearisation point (copied values).
struct PriorBlock {
  BlockKind kind = BlockKind::kEuclidean;
  int ambient_size = 0;
  int tangent_size = 0;
  std::vector<double> x0;
};

class MarginalizationPrior final : public ceres::CostFunction {
 public:
  // J: m×n with n = Σ blocks[k].tangent_size; r0: m. Parameter blocks, in Evaluate and in
  // Problem::AddResidualBlock, are in the order of `blocks`.
  MarginalizationPrior(std::vector<PriorBlock> blocks, MatX J, VecX r0);

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  const std::vector<PriorBlock>& blocks() const { return blocks_; }
  const MatX& J() const { return J_; }
  const VecX& r0() const { return r0_; }

 private:
  std::vector<PriorBlock> blocks_;
  std::vector<int> tangent_offsets_;
  MatX J_;
  VecX r0_;
};

// Collects residual blocks and parameter blocks, evaluates them at the blocks' current values and
// Schur-complements the marginalised blocks out:
//   H = Σ JᵀJ, b = Σ Jᵀr  (tangent space: ambient Jacobians times PlusJacobian at the current point;
//   a loss function rescales r and J as Ceres's Corrector does),
//   H* = H_kk − H_km·H_mm⁺·H_mk,  b* = b_k − H_km·H_mm⁺·b_m   (H_mm⁺: eigen-decomposition pseudo-inverse),
//   H* = V·Λ·Vᵀ  →  J = √Λ·Vᵀ,  r0 = √Λ⁻¹·Vᵀ·b*   over the eigenvalues above the threshold.
// Add exactly the residual blocks that touch a marginalised block (others would be counted twice: once in
// the prior and once in the problem). Nothing is owned: cost and loss functions and parameter memory must
// outlive Marginalize().
class MarginalizationInfo {
 public:
  enum class Role { kMarginalize, kKeep, kConstant };

  struct Options {
    // Eigenvalues of H_mm and H* at or below max(absolute, relative·λmax) count as zero: absolute as in
    // VINS-Mono; relative ≈ 1e4·ε, the round-off level of the null space of an information matrix.
    double eigenvalue_threshold_absolute = 1e-8;
    double eigenvalue_threshold_relative = 1e-12;
  };

  MarginalizationInfo() = default;
  explicit MarginalizationInfo(const Options& options) : options_(options) {}

  // Declares a parameter block. Every block a residual touches must be declared. kConstant blocks are
  // held fixed (no Jacobian, no prior column): use it for blocks held constant in the problem.
  void AddParameterBlock(double* values, BlockKind kind, int ambient_size, Role role);

  // Adds a residual block (as it is in the problem). loss may be null.
  void AddResidualBlock(const ceres::CostFunction* cost, const ceres::LossFunction* loss,
                        std::vector<double*> parameter_blocks);

  // Evaluates and Schur-complements. Returns false (prior left empty) if a cost function fails to
  // evaluate or a value is not finite.
  bool Marginalize();

  // After Marginalize(): the kept blocks that some residual touches, in declaration order — the parameter
  // blocks to pass with the prior — and the prior itself (null when nothing is kept or no information
  // remains). The caller owns the returned cost function.
  const std::vector<double*>& kept_parameter_blocks() const { return kept_blocks_; }
  std::unique_ptr<MarginalizationPrior> CreatePrior() const;

  // Marginal information and gradient in tangent space over kept_parameter_blocks() (for tests, and for
  // a covariance of the oldest kept state).
  const MatX& marginal_information() const { return H_marg_; }
  const VecX& marginal_gradient() const { return b_marg_; }

 private:
  struct Block {
    double* values;
    BlockKind kind;
    int ambient_size;
    int tangent_size;
    Role role;
    int offset = -1;  // tangent column in H (marginalised first, then kept)
    bool used = false;
  };
  struct Residual {
    const ceres::CostFunction* cost;
    const ceres::LossFunction* loss;
    std::vector<double*> parameter_blocks;
  };
  int FindBlock(const double* values) const;
  // Gives each used block its tangent column (marginalised first, then kept); returns the marginalised
  // dimension and sets *n to the total.
  int LayOutTangents(int* n);
  // Adds one residual's JᵀJ and Jᵀr (tangent space, loss applied) to H and b; false if it fails to evaluate.
  bool Accumulate(const Residual& res, MatX* H, VecX* b) const;

  Options options_;
  std::vector<Block> blocks_;
  std::vector<Residual> residuals_;
  std::vector<double*> kept_blocks_;
  std::vector<PriorBlock> kept_descriptions_;
  MatX H_marg_, J_prior_;
  VecX b_marg_, r0_prior_;
};

}  // namespace gins
