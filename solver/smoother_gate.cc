#include "solver/smoother_gate.h"

#include <Eigen/Cholesky>

#include <utility>

namespace gins {
namespace {

// Block-order tangent index of each NavState coordinate (−1 outside NavState), and the process noise per
// second of the coordinates outside it (their blocks' random walks).
struct Layout {
  std::vector<int> nav_of;
  std::vector<std::pair<int, double>> walks;  // (block-order index, σ² per s)
  int n = 0;
};

Layout LayoutOf(const std::vector<BlockType>& types, const SensorOptions& options) {
  Layout l;
  l.nav_of = NavIndexOfTangent(types);
  l.n = static_cast<int>(l.nav_of.size());
  int offset = 0;
  for (BlockType type : types) {
    const BlockSpec& spec = SpecOf(type);
    if (spec.num_runs == 0) {
      const double sigma = spec.random_walk_sigma != nullptr ? spec.random_walk_sigma(options) : 0.0;
      for (int k = 0; k < spec.tangent_size; ++k) l.walks.emplace_back(offset + k, sigma * sigma);
    }
    offset += spec.tangent_size;
  }
  return l;
}

}  // namespace

MatX PredictBlockCovariance(const std::vector<BlockType>& types, const MatX& cov_i, const NavState& x_i,
                            const Preintegration& pre, const SensorOptions& options, MatX* joint) {
  const Layout l = LayoutOf(types, options);
  // Φ and Q in block order: NavState's through the preintegration, the other blocks random walks.
  Mat15 Phi15, Q15;
  PredictedTransition(x_i, pre, options.imu.gyro_bias_rw, options.imu.acc_bias_rw, &Phi15, &Q15);
  MatX Phi = MatX::Zero(l.n, l.n), Q = MatX::Zero(l.n, l.n);
  for (int r = 0; r < l.n; ++r) {
    for (int c = 0; c < l.n; ++c) {
      if (l.nav_of[r] >= 0 && l.nav_of[c] >= 0) {
        Phi(r, c) = Phi15(l.nav_of[r], l.nav_of[c]);
        Q(r, c) = Q15(l.nav_of[r], l.nav_of[c]);
      }
    }
  }
  for (const auto& [k, q] : l.walks) {
    Phi(k, k) = 1.0;
    Q(k, k) = q * pre.dt();
  }
  const MatX cross = Phi * cov_i;  // cov(j, i)
  MatX cov_j = cross * Phi.transpose() + Q;
  cov_j = 0.5 * (cov_j + cov_j.transpose());
  if (joint != nullptr) {
    joint->resize(2 * l.n, 2 * l.n);
    joint->topLeftCorner(l.n, l.n) = cov_i;
    joint->bottomLeftCorner(l.n, l.n) = cross;
    joint->topRightCorner(l.n, l.n) = cross.transpose();
    joint->bottomRightCorner(l.n, l.n) = cov_j;
  }
  return cov_j;
}

MatX SubCovariance(const std::vector<BlockType>& types, const MatX& cov, const std::vector<BlockType>& wanted,
                   int keyframe) {
  // Offsets of each estimated block within one keyframe's tangent.
  std::vector<int> index;
  int per_keyframe = 0;
  for (BlockType t : types) per_keyframe += SpecOf(t).tangent_size;
  for (BlockType w : wanted) {
    int offset = keyframe * per_keyframe;
    for (BlockType t : types) {
      if (t == w) {
        for (int k = 0; k < SpecOf(t).tangent_size; ++k) index.push_back(offset + k);
        break;
      }
      offset += SpecOf(t).tangent_size;
    }
  }
  const int m = static_cast<int>(index.size());
  MatX out(m, m);
  for (int r = 0; r < m; ++r) {
    for (int c = 0; c < m; ++c) out(r, c) = cov(index[r], index[c]);
  }
  return out;
}

FactorCheck CheckFactor(const ceres::CostFunction& cost, const std::vector<const double*>& params,
                        const std::vector<BlockKind>& kinds, const MatX& sigma, bool posterior) {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  FactorCheck c;
  const int m = cost.num_residuals();
  const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
  std::vector<RowMajor> J_amb(sizes.size());
  std::vector<double*> jac_ptrs;
  for (size_t k = 0; k < sizes.size(); ++k) {
    J_amb[k].resize(m, sizes[k]);
    jac_ptrs.push_back(J_amb[k].data());
  }
  c.residual.resize(m);
  if (!cost.Evaluate(params.data(), c.residual.data(), jac_ptrs.data()) || !c.residual.allFinite()) return c;
  // Tangent Jacobian, block after block.
  MatX J(m, sigma.cols());
  int col = 0;
  for (size_t k = 0; k < sizes.size(); ++k) {
    const int tangent = TangentSizeOf(kinds[k], sizes[k]);
    if (kinds[k] == BlockKind::kPose) {
      Eigen::Matrix<double, pose::kAmbient, pose::kTangent, Eigen::RowMajor> P;
      PoseManifold().PlusJacobian(params[k], P.data());
      J.middleCols(col, tangent) = J_amb[k] * P;
    } else {
      J.middleCols(col, tangent) = J_amb[k];
    }
    col += tangent;
  }
  if (!J.allFinite() || col != sigma.cols()) return c;
  c.S = (posterior ? -1.0 : 1.0) * (J * sigma * J.transpose()) + MatX::Identity(m, m);
  const Eigen::LLT<MatX> llt(c.S);
  if (llt.info() != Eigen::Success) return c;
  c.chi2 = c.residual.dot(llt.solve(c.residual));
  c.evaluated = std::isfinite(c.chi2);
  return c;
}

}  // namespace gins
