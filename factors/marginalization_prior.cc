#include "factors/marginalization_prior.h"

#include <glog/logging.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "factors/pose_manifold.h"

namespace gins {

namespace {

using RowMajorMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// ∂Minus(x, x0)/∂x at x (tangent × ambient).
MatX MinusJacobianAt(BlockKind kind, int ambient_size, const double* x, const double* x0) {
  if (kind == BlockKind::kPose) {
    Eigen::Matrix<double, pose::kTangent, pose::kAmbient, Eigen::RowMajor> D;
    PoseManifold::MinusJacobianAt(x, x0, D.data());
    return D;
  }
  return MatX::Identity(ambient_size, ambient_size);
}

// ∂Plus(x, δ)/∂δ at δ = 0 (ambient × tangent).
MatX PlusJacobianAt(BlockKind kind, int ambient_size, const double* x) {
  if (kind == BlockKind::kPose) {
    Eigen::Matrix<double, pose::kAmbient, pose::kTangent, Eigen::RowMajor> P;
    PoseManifold().PlusJacobian(x, P.data());
    return P;
  }
  return MatX::Identity(ambient_size, ambient_size);
}

// Symmetric eigen-decomposition with eigenvalues at or below the threshold treated as zero.
struct TruncatedEigen {
  VecX lambda;  // kept eigenvalues
  MatX V;       // their eigenvectors (columns)
};
TruncatedEigen Truncate(const MatX& H, double abs_threshold, double rel_threshold) {
  const Eigen::SelfAdjointEigenSolver<MatX> es(0.5 * (H + H.transpose()));
  const VecX& lambda = es.eigenvalues();
  const double lambda_max = lambda.size() > 0 ? std::max(lambda.maxCoeff(), 0.0) : 0.0;
  const double threshold = std::max(abs_threshold, rel_threshold * lambda_max);
  std::vector<int> keep;
  for (int k = 0; k < lambda.size(); ++k) {
    if (lambda[k] > threshold) keep.push_back(k);
  }
  TruncatedEigen out;
  out.lambda.resize(static_cast<int>(keep.size()));
  out.V.resize(H.rows(), static_cast<int>(keep.size()));
  for (int c = 0; c < static_cast<int>(keep.size()); ++c) {
    out.lambda[c] = lambda[keep[c]];
    out.V.col(c) = es.eigenvectors().col(keep[c]);
  }
  return out;
}

}  // namespace

int TangentSizeOf(BlockKind kind, int ambient_size) {
  if (kind == BlockKind::kPose) {
    CHECK_EQ(ambient_size, pose::kAmbient) << "a pose block has 7 doubles";
    return pose::kTangent;
  }
  return ambient_size;
}

// ---------------------------------------------------------------------------------------------------------
// MarginalizationPrior

MarginalizationPrior::MarginalizationPrior(std::vector<PriorBlock> blocks, MatX J, VecX r0)
    : blocks_(std::move(blocks)), J_(std::move(J)), r0_(std::move(r0)) {
  int n = 0;
  for (const PriorBlock& b : blocks_) {
    CHECK_EQ(b.tangent_size, TangentSizeOf(b.kind, b.ambient_size));
    CHECK_EQ(static_cast<int>(b.x0.size()), b.ambient_size);
    tangent_offsets_.push_back(n);
    n += b.tangent_size;
    mutable_parameter_block_sizes()->push_back(b.ambient_size);
  }
  CHECK_EQ(J_.cols(), n) << "prior Jacobian columns must equal the sum of the blocks' tangent sizes";
  CHECK_EQ(J_.rows(), r0_.size());
  CHECK_GT(J_.rows(), 0) << "empty prior";
  set_num_residuals(static_cast<int>(J_.rows()));
}

bool MarginalizationPrior::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  const int m = static_cast<int>(J_.rows());
  VecX dx(J_.cols());
  for (size_t k = 0; k < blocks_.size(); ++k) {
    const PriorBlock& b = blocks_[k];
    const double* x = parameters[k];
    if (b.kind == BlockKind::kPose) {
      PoseManifold().Minus(x, b.x0.data(), dx.data() + tangent_offsets_[k]);
    } else {
      for (int i = 0; i < b.ambient_size; ++i) dx[tangent_offsets_[k] + i] = x[i] - b.x0[i];
    }
  }
  Eigen::Map<VecX> r(residuals, m);
  r = r0_ + J_ * dx;
  if (!r.allFinite()) return false;

  if (jacobians != nullptr) {
    for (size_t k = 0; k < blocks_.size(); ++k) {
      if (jacobians[k] == nullptr) continue;
      const PriorBlock& b = blocks_[k];
      Eigen::Map<RowMajorMat> J_res_x(jacobians[k], m, b.ambient_size);
      J_res_x = J_.middleCols(tangent_offsets_[k], b.tangent_size) *
                MinusJacobianAt(b.kind, b.ambient_size, parameters[k], b.x0.data());
    }
  }
  return true;
}

// ---------------------------------------------------------------------------------------------------------
// MarginalizationInfo

void MarginalizationInfo::AddParameterBlock(double* values, BlockKind kind, int ambient_size, Role role) {
  CHECK(values != nullptr);
  CHECK_LT(FindBlock(values), 0) << "parameter block declared twice";
  blocks_.push_back(Block{values, kind, ambient_size, TangentSizeOf(kind, ambient_size), role});
}

void MarginalizationInfo::AddResidualBlock(const ceres::CostFunction* cost, const ceres::LossFunction* loss,
                                           std::vector<double*> parameter_blocks) {
  CHECK(cost != nullptr);
  CHECK_EQ(cost->parameter_block_sizes().size(), parameter_blocks.size());
  for (size_t i = 0; i < parameter_blocks.size(); ++i) {
    const int k = FindBlock(parameter_blocks[i]);
    CHECK_GE(k, 0) << "residual touches an undeclared parameter block";
    CHECK_EQ(blocks_[k].ambient_size, cost->parameter_block_sizes()[i]) << "parameter block size mismatch";
  }
  residuals_.push_back(Residual{cost, loss, std::move(parameter_blocks)});
}

int MarginalizationInfo::FindBlock(const double* values) const {
  for (size_t k = 0; k < blocks_.size(); ++k) {
    if (blocks_[k].values == values) return static_cast<int>(k);
  }
  return -1;
}

int MarginalizationInfo::LayOutTangents(int* n_total) {
  for (Block& b : blocks_) b.used = false;
  for (const Residual& res : residuals_) {
    for (double* p : res.parameter_blocks) blocks_[FindBlock(p)].used = true;
  }
  int n = 0;
  for (Block& b : blocks_) {
    if (b.used && b.role == Role::kMarginalize) {
      b.offset = n;
      n += b.tangent_size;
    }
  }
  const int n_marg = n;
  for (Block& b : blocks_) {
    if (b.used && b.role == Role::kKeep) {
      b.offset = n;
      n += b.tangent_size;
    }
  }
  *n_total = n;
  return n_marg;
}

bool MarginalizationInfo::Accumulate(const Residual& res, MatX* H, VecX* b_vec) const {
  const int m = res.cost->num_residuals();
  const size_t num_blocks = res.parameter_blocks.size();
  std::vector<int> index(num_blocks);
  std::vector<RowMajorMat> J_amb(num_blocks);
  std::vector<double*> jac_ptrs(num_blocks, nullptr);
  for (size_t i = 0; i < num_blocks; ++i) {
    index[i] = FindBlock(res.parameter_blocks[i]);
    const Block& blk = blocks_[index[i]];
    if (blk.role == Role::kConstant) continue;
    J_amb[i].resize(m, blk.ambient_size);
    jac_ptrs[i] = J_amb[i].data();
  }
  VecX r(m);
  if (!res.cost->Evaluate(res.parameter_blocks.data(), r.data(), jac_ptrs.data())) return false;
  if (!r.allFinite()) return false;
  for (size_t i = 0; i < num_blocks; ++i) {
    if (jac_ptrs[i] != nullptr && !J_amb[i].allFinite()) return false;
  }

  // Robust loss: rescale as Ceres's Corrector does, so that JᵀJ and Jᵀr are those the solver sees.
  if (res.loss != nullptr) {
    const double sq_norm = r.squaredNorm();
    double rho[3];
    res.loss->Evaluate(sq_norm, rho);
    if (!(rho[1] > 0.0) || !std::isfinite(rho[1])) return false;
    const double sqrt_rho1 = std::sqrt(rho[1]);
    double residual_scaling = sqrt_rho1, alpha_sq_norm = 0.0;
    if (sq_norm > 0.0 && rho[2] > 0.0) {
      const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * sq_norm * rho[2] / rho[1]);
      residual_scaling = sqrt_rho1 / (1.0 - alpha);
      alpha_sq_norm = alpha / sq_norm;
    }
    for (size_t i = 0; i < num_blocks; ++i) {
      if (jac_ptrs[i] == nullptr) continue;
      const Eigen::RowVectorXd rT_J = r.transpose() * J_amb[i];
      J_amb[i] = sqrt_rho1 * (J_amb[i] - alpha_sq_norm * r * rT_J);
    }
    r *= residual_scaling;
  }

  for (size_t i = 0; i < num_blocks; ++i) {
    if (jac_ptrs[i] == nullptr) continue;
    const Block& bi = blocks_[index[i]];
    const MatX J_i = J_amb[i] * PlusJacobianAt(bi.kind, bi.ambient_size, bi.values);
    b_vec->segment(bi.offset, bi.tangent_size) += J_i.transpose() * r;
    for (size_t j = 0; j < num_blocks; ++j) {
      if (jac_ptrs[j] == nullptr) continue;
      const Block& bj = blocks_[index[j]];
      const MatX J_j = J_amb[j] * PlusJacobianAt(bj.kind, bj.ambient_size, bj.values);
      H->block(bi.offset, bj.offset, bi.tangent_size, bj.tangent_size) += J_i.transpose() * J_j;
    }
  }
  return true;
}

bool MarginalizationInfo::Marginalize() {
  kept_blocks_.clear();
  kept_descriptions_.clear();
  H_marg_.resize(0, 0);
  b_marg_.resize(0);
  J_prior_.resize(0, 0);
  r0_prior_.resize(0);

  // Tangent layout: marginalised blocks first, then kept ones, each in declaration order.
  int n = 0;
  const int n_marg = LayOutTangents(&n);
  const int n_keep = n - n_marg;
  MatX H = MatX::Zero(n, n);
  VecX b_vec = VecX::Zero(n);
  for (const Residual& res : residuals_) {
    if (!Accumulate(res, &H, &b_vec)) return false;
  }

  // Schur complement of the marginalised blocks, with a pseudo-inverse of H_mm: directions the residuals
  // do not constrain carry no information to pass on.
  const MatX H_mm = H.topLeftCorner(n_marg, n_marg);
  const MatX H_km = H.bottomLeftCorner(n_keep, n_marg);
  const TruncatedEigen eig_mm =
      Truncate(H_mm, options_.eigenvalue_threshold_absolute, options_.eigenvalue_threshold_relative);
  const MatX H_mm_pinv = eig_mm.V * eig_mm.lambda.cwiseInverse().asDiagonal() * eig_mm.V.transpose();
  H_marg_ = H.bottomRightCorner(n_keep, n_keep) - H_km * H_mm_pinv * H_km.transpose();
  H_marg_ = 0.5 * (H_marg_ + H_marg_.transpose());
  b_marg_ = b_vec.tail(n_keep) - H_km * H_mm_pinv * b_vec.head(n_marg);

  for (const Block& blk : blocks_) {
    if (!(blk.used && blk.role == Role::kKeep)) continue;
    kept_blocks_.push_back(blk.values);
    kept_descriptions_.push_back(PriorBlock{blk.kind, blk.ambient_size, blk.tangent_size,
                                            std::vector<double>(blk.values, blk.values + blk.ambient_size)});
  }

  // Factor H* = JᵀJ with b* = Jᵀr0 over the non-negligible eigenvalues.
  const TruncatedEigen eig =
      Truncate(H_marg_, options_.eigenvalue_threshold_absolute, options_.eigenvalue_threshold_relative);
  const VecX sqrt_lambda = eig.lambda.cwiseSqrt();
  J_prior_ = sqrt_lambda.asDiagonal() * eig.V.transpose();
  r0_prior_ = sqrt_lambda.cwiseInverse().asDiagonal() * (eig.V.transpose() * b_marg_);
  return H_marg_.allFinite() && b_marg_.allFinite();
}

std::unique_ptr<MarginalizationPrior> MarginalizationInfo::CreatePrior() const {
  if (kept_blocks_.empty() || J_prior_.rows() == 0) return nullptr;
  return std::make_unique<MarginalizationPrior>(kept_descriptions_, J_prior_, r0_prior_);
}

}  // namespace gins
