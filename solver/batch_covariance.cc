// The whole-log smoother's covariances (the band's block-tridiagonal recursion), the revisit of the gated
// factors against them, and the summary's time offset.
#include "solver/batch_smoother.h"

#include <ceres/crs_matrix.h>
#include <glog/logging.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>

#include "solver/estimator_common.h"
#include "solver/smoother_gate.h"

namespace gins {
namespace {

// S⁻¹ of a symmetric positive definite block; false if it is not.
bool InverseSpd(const MatX& S, MatX* inv) {
  const Eigen::LLT<MatX> llt(0.5 * (S + S.transpose()));
  if (llt.info() != Eigen::Success) return false;
  *inv = llt.solve(MatX::Identity(S.rows(), S.cols()));
  return inv->allFinite();
}

}  // namespace

bool BatchSmoother::Revisit(FactorLog* log, int first, int last, const std::vector<MatX>& cov) {
  bool changed = false;
  for (const FactorSpan& f : factors_) {
    if (f.lo < first || f.hi >= last || f.lo != f.hi) continue;
    const LoggedFactor& lf = log->factors()[f.log_index];
    if (!lf.revisitable()) continue;
    std::vector<const double*> params;
    std::vector<BlockKind> kinds;
    std::vector<BlockType> types;
    for (const BlockRef& ref : lf.blocks) {
      params.push_back(ref.kf->block(ref.type));
      kinds.push_back(SpecOf(ref.type).kind);
      types.push_back(ref.type);
    }
    // The keyframe's covariance over the factor's blocks (their tangents in the factor's order; a block not
    // estimated leaves it short, and CheckFactor refuses).
    const MatX sigma = SubCovariance(types_, cov[f.lo - first], types);
    // A used measurement is part of the solution: its residual's covariance is R − HPHᵀ; an unused one is
    // predicted by it: R + HPHᵀ. The same χ² gate as the window's.
    const FactorCheck check = CheckFactor(*lf.cost, params, kinds, sigma, /*posterior=*/lf.active);
    if (!check.evaluated) continue;
    const bool passes = check.chi2 <= lf.gate;
    if (lf.active && !passes) {
      log->SetActive(f.log_index, false);
      ++stats_.revisit_dropped;
      changed = true;
    } else if (!lf.active && passes) {
      log->SetActive(f.log_index, true);
      ++stats_.revisit_restored;
      changed = true;
    }
  }
  return changed;
}

bool BatchSmoother::RecoverCovariances(ceres::Problem* problem, const std::vector<FactorSpan>& spans, int first,
                                       int last, std::vector<MatX>* cov) {
  const int n_kf = last - first;
  int w = 1;
  for (const FactorSpan& f : spans) w = std::max(w, f.hi - f.lo);
  int per = 0;
  for (BlockType t : types_) per += SpecOf(t).tangent_size;
  ceres::Problem::EvaluateOptions eo;
  for (int k = first; k < last; ++k) {
    for (BlockType t : types_) eo.parameter_blocks.push_back(kfs_[k]->block(t));
  }
  ceres::CRSMatrix J;
  if (!problem->Evaluate(eo, nullptr, nullptr, nullptr, &J) || J.num_cols != per * n_kf) return false;

  // H = JᵀJ in groups of w keyframes: block-tridiagonal (D_g on the diagonal, B_g = H(g, g+1) above it),
  // accumulated row by row from the sparse Jacobian.
  const int n = per * w;
  const int n_groups = (n_kf + w - 1) / w;
  auto group_size = [&](int g) { return per * (std::min(n_kf, (g + 1) * w) - g * w); };
  std::vector<MatX> D(n_groups), B(std::max(0, n_groups - 1));
  for (int g = 0; g < n_groups; ++g) D[g] = MatX::Zero(group_size(g), group_size(g));
  for (int g = 0; g + 1 < n_groups; ++g) B[g] = MatX::Zero(group_size(g), group_size(g + 1));
  for (int r = 0; r < J.num_rows; ++r) {
    for (int a = J.rows[r]; a < J.rows[r + 1]; ++a) {
      const int ca = J.cols[a], ga = ca / n;
      for (int b = J.rows[r]; b < J.rows[r + 1]; ++b) {
        const int cb = J.cols[b], gb = cb / n;
        const double v = J.values[a] * J.values[b];
        if (ga == gb) {
          D[ga](ca - ga * n, cb - gb * n) += v;
        } else if (gb == ga + 1) {
          B[ga](ca - ga * n, cb - gb * n) += v;
        } else if (ga != gb + 1) {
          LOG(WARNING) << "batch: a factor spans more than the band; no covariances";
          return false;
        }
      }
    }
  }
  // Forward: S_g = D_g - B_{g-1}ᵀ S_{g-1}⁻¹ B_{g-1}. Backward: Σ_g = S_g⁻¹ + S_g⁻¹ B_g Σ_{g+1} B_gᵀ S_g⁻¹.
  std::vector<MatX> S_inv(n_groups);
  for (int g = 0; g < n_groups; ++g) {
    MatX S = D[g];
    if (g > 0) S -= B[g - 1].transpose() * S_inv[g - 1] * B[g - 1];
    if (!InverseSpd(S, &S_inv[g])) {
      LOG(WARNING) << "batch: information not positive definite at keyframe " << first + g * w << "; no covariances";
      return false;
    }
  }
  cov->assign(n_kf, MatX::Zero(per, per));
  MatX sigma_next;
  for (int g = n_groups - 1; g >= 0; --g) {
    MatX sigma = S_inv[g];
    if (g + 1 < n_groups) {
      const MatX K = S_inv[g] * B[g];
      sigma += K * sigma_next * K.transpose();
    }
    for (int k = g * w; k < std::min(n_kf, (g + 1) * w); ++k) {
      const int o = (k - g * w) * per;
      (*cov)[k] = sigma.block(o, o, per, per);
    }
    sigma_next = std::move(sigma);
  }
  return true;
}

nlohmann::json BatchSmoother::TimeOffset() const {
  const double td = kfs_.empty() ? 0.0 : kfs_.back()->block(BlockType::kTimeOffset)[0];
  double sigma = 0.0;
  if (estimated_[static_cast<int>(BlockType::kTimeOffset)] && last_block_cov_.size() > 0) {
    sigma = std::sqrt(std::max(SubCovariance(types_, last_block_cov_, {BlockType::kTimeOffset})(0, 0), 0.0));
  }
  return TimeOffsetJson(sensors_.gnss, td, sigma);
}

}  // namespace gins
