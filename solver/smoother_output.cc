#include "solver/smoother_output.h"

#include <ceres/crs_matrix.h>

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "core/imu_kernel.h"

namespace gins {

StateEstimate EstimateOf(const Keyframe& kf, const Mat15* cov) {
  StateEstimate e;
  e.x = kf.State();
  e.odom_scale = kf.block(BlockType::kScale)[0];
  if (cov != nullptr) {
    e.sigma_p = cov->block<3, 3>(nav::kP, nav::kP).diagonal().cwiseSqrt();
    e.sigma_v = cov->block<3, 3>(nav::kV, nav::kV).diagonal().cwiseSqrt();
    const Mat3 R_wb = e.x.R_wb();
    e.sigma_att = (R_wb * cov->block<3, 3>(nav::kTheta, nav::kTheta) * R_wb.transpose()).diagonal().cwiseSqrt();
  }
  return e;
}

namespace {

using SpMat = Eigen::SparseMatrix<double>;

// Columns `columns` of H⁻¹ (H the window's information, JᵀJ). The sparse LDLᵀ first (the common case, bit for
// bit as before); it is accepted only with every pivot positive and every variance it gives positive and
// finite. A window whose coasted interval (an IMU gap, a long outage) makes H ill-conditioned can give a
// factorisation that "succeeds" with non-positive pivots (negative variances, NaN σ): then the same on H
// scaled to unit diagonal, and failing that (numerically singular) its eigen-decomposition with eigenvalues
// floored at 1e-12 of the largest (a direction the data do not constrain gets a large, finite variance).
// False only when H is not finite.
bool InverseColumns(const SpMat& H, const std::vector<int>& columns, MatX* C) {
  const int m = static_cast<int>(columns.size());
  MatX E = MatX::Zero(H.rows(), m);
  for (int k = 0; k < m; ++k) E(columns[k], k) = 1.0;
  const auto usable = [&](const Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::NaturalOrdering<int>>& ldlt) {
    return ldlt.info() == Eigen::Success && (ldlt.vectorD().array() > 0.0).all();
  };
  const auto positive = [&](const MatX& c) {
    if (!c.allFinite()) return false;
    for (int k = 0; k < m; ++k) {
      if (!(c(columns[k], k) > 0.0)) return false;
    }
    return true;
  };
  {
    const Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt(H);
    if (usable(ldlt)) {
      *C = ldlt.solve(E);
      if (ldlt.info() == Eigen::Success && positive(*C)) return true;
    }
  }
  // Scaled to unit diagonal (the coasted interval's information is orders of magnitude below the rest).
  VecX s = VecX::Ones(H.rows());
  for (int i = 0; i < H.rows(); ++i) {
    const double d = H.coeff(i, i);
    if (d > 0.0 && std::isfinite(d)) s[i] = 1.0 / std::sqrt(d);
  }
  const SpMat Hs = s.asDiagonal() * H * s.asDiagonal();
  {
    const Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt(Hs);
    if (usable(ldlt)) {
      *C = s.asDiagonal() * ldlt.solve(MatX(s.asDiagonal() * E));
      if (ldlt.info() == Eigen::Success && positive(*C)) return true;
    }
  }
  // Numerically singular: the eigen-decomposition, eigenvalues floored.
  MatX Hd = Hs.toDense();
  if (!Hd.allFinite()) return false;
  Hd = 0.5 * (Hd + Hd.transpose()).eval();
  const Eigen::SelfAdjointEigenSolver<MatX> es(Hd);
  if (es.info() != Eigen::Success) return false;
  const double floor = std::max(1e-12 * es.eigenvalues().maxCoeff(), 1e-300);
  const VecX inv = es.eigenvalues().cwiseMax(floor).cwiseInverse();
  const MatX Es = es.eigenvectors().transpose() * (s.asDiagonal() * E);
  *C = s.asDiagonal() * (es.eigenvectors() * (inv.asDiagonal() * Es));
  return C->allFinite();
}

// H = JᵀJ of a CRS Jacobian, accumulated row by row (Σ rᵢᵀrᵢ) into a dense matrix and kept sparse (exact
// zeros dropped). The window's rows touch one or two keyframes: 20 % fewer instructions than Eigen's
// general sparse-sparse product, which spends them on structure bookkeeping. Each column's touched rows form
// one range (its band), so only the bands are read out and cleared: the dense scratch is zeroed once per
// thread and size, not per call.
SpMat Information(const ceres::CRSMatrix& J) {
  const int n = J.num_cols;
  thread_local MatX scratch;
  if (scratch.rows() != n) scratch = MatX::Zero(n, n);
  MatX& H = scratch;
  std::vector<int> lo(n, n), hi(n, -1);
  for (int r = 0; r < J.num_rows; ++r) {
    const int begin = J.rows[r], end = J.rows[r + 1];
    if (begin == end) continue;
    const auto [c_min, c_max] = std::minmax_element(J.cols.begin() + begin, J.cols.begin() + end);
    for (int a = begin; a < end; ++a) {
      const int c = J.cols[a];
      lo[c] = std::min(lo[c], *c_min);
      hi[c] = std::max(hi[c], *c_max);
      const double va = J.values[a];
      if (va == 0.0) continue;
      for (int b = begin; b < end; ++b) H(c, J.cols[b]) += va * J.values[b];
    }
  }
  int nnz = 0;
  for (int c = 0; c < n; ++c) nnz += std::max(0, hi[c] - lo[c] + 1);
  SpMat out(n, n);
  out.reserve(nnz);
  for (int c = 0; c < n; ++c) {
    out.startVec(c);
    for (int r = lo[c]; r <= hi[c]; ++r) {
      if (H(r, c) != 0.0) out.insertBack(r, c) = H(r, c);
      H(r, c) = 0.0;
    }
  }
  out.finalize();
  return out;
}

}  // namespace

// The window is a chain, so H is banded: a sparse JᵀJ and a sparse LDLᵀ in the natural (time) order cost a
// few hundred µs where dense ones cost milliseconds per keyframe.
bool LeadingCovariance(ceres::Problem* problem, const std::vector<double*>& blocks, const std::vector<int>& nav_index,
                       Mat15* cov) {
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = blocks;
  ceres::CRSMatrix J;
  if (!problem->Evaluate(eo, nullptr, nullptr, nullptr, &J)) return false;
  const int n = static_cast<int>(nav_index.size());
  if (J.num_cols < n) return false;
  std::vector<int> columns;  // the leading columns that are NavState coordinates
  for (int i = 0; i < n; ++i) {
    if (nav_index[i] >= 0) columns.push_back(i);
  }
  const int m = static_cast<int>(columns.size());
  const SpMat H = Information(J);
  MatX C;
  if (!InverseColumns(H, columns, &C)) return false;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) (*cov)(nav_index[columns[i]], nav_index[columns[j]]) = C(columns[i], j);
  }
  return cov->allFinite();
}

bool WindowCovariances(KeyframeStore& store, int trailing, MatX* trailing_cov, MatX* oldest_cov) {
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = store.EstimatedBlocks();
  ceres::CRSMatrix J;
  if (!store.problem()->Evaluate(eo, nullptr, nullptr, nullptr, &J)) return false;
  int per = 0;
  for (BlockType t : store.EstimatedTypes()) per += SpecOf(t).tangent_size;
  const int n = per * static_cast<int>(store.size());
  trailing = std::min(trailing, static_cast<int>(store.size()));
  if (J.num_cols != n || trailing < 1) return false;
  const SpMat H = Information(J);
  const int t = trailing * per;
  const auto symmetric = [](const MatX& c) { return MatX(0.5 * (c + c.transpose())); };
  const auto positive = [](const MatX& c) { return c.allFinite() && (c.diagonal().array() > 0.0).all(); };
  {
    // H = L·D·Lᵀ in the natural (time) order, L unit lower triangular: H⁻¹ = L⁻ᵀ·D⁻¹·L⁻¹ with L⁻¹ lower
    // triangular too, so the trailing block of H⁻¹ needs only the trailing blocks of L and D:
    // (H⁻¹)_TT = L_TT⁻ᵀ·D_T⁻¹·L_TT⁻¹. A t×t dense inverse instead of t solves through the whole window.
    // (Moving the oldest keyframe into the trailing block too was measured no faster: the fill it makes
    // costs what its solves cost.)
    const Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt(H);
    if (ldlt.info() == Eigen::Success && (ldlt.vectorD().array() > 0.0).all()) {
      const MatX L_tt = ldlt.matrixL().nestedExpression().bottomRightCorner(t, t).toDense();
      const MatX W = L_tt.triangularView<Eigen::UnitLower>().solve(MatX::Identity(t, t));
      const MatX C = W.transpose() * ldlt.vectorD().tail(t).cwiseInverse().asDiagonal() * W;
      bool ok = positive(C);
      MatX C0;
      if (ok && oldest_cov != nullptr) {
        // The oldest block the same way from the other end: (H⁻¹)_00 = Xᵀ·D⁻¹·X with X = L⁻¹·E, E its unit
        // columns; one triangular solve, not the forward and backward pair of a full solve.
        MatX X = MatX::Zero(n, per);
        X.topRows(per).setIdentity();
        ldlt.matrixL().solveInPlace(X);
        C0 = X.transpose() * ldlt.vectorD().cwiseInverse().asDiagonal() * X;
        ok = positive(C0);
      }
      if (ok) {
        *trailing_cov = symmetric(C);
        if (oldest_cov != nullptr) *oldest_cov = symmetric(C0);
        return true;
      }
    }
  }
  // An ill-conditioned window (see InverseColumns): the guarded column solves.
  std::vector<int> columns;
  if (oldest_cov != nullptr) {
    for (int i = 0; i < per; ++i) columns.push_back(i);
  }
  for (int i = n - t; i < n; ++i) columns.push_back(i);
  MatX C;
  if (!InverseColumns(H, columns, &C)) return false;
  const int m = static_cast<int>(columns.size());
  MatX joint(m, m);
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) joint(i, j) = C(columns[i], j);
  }
  joint = symmetric(joint);
  if (!joint.allFinite()) return false;
  *trailing_cov = joint.bottomRightCorner(t, t);
  if (oldest_cov != nullptr) *oldest_cov = joint.topLeftCorner(per, per);
  return true;
}

Mat15 NavCovariance(const std::vector<BlockType>& types, const MatX& block_cov) {
  const std::vector<int> nav = NavIndexOfTangent(types);
  Mat15 P = Mat15::Zero();
  for (size_t i = 0; i < nav.size(); ++i) {
    for (size_t j = 0; j < nav.size(); ++j) {
      if (nav[i] >= 0 && nav[j] >= 0) P(nav[i], nav[j]) = block_cov(i, j);
    }
  }
  return P;
}

bool OldestCovariance(KeyframeStore& store, Mat15* cov) {
  return LeadingCovariance(store.problem(), store.EstimatedBlocks(), NavIndexOfTangent(store.EstimatedTypes()), cov);
}

void EmitFinal(const Keyframe& kf, const Keyframe* next, const std::vector<HeldImuSample>& tail, const Mat15* cov,
               const ImuEarthTerms& earth, const StateCallback& on_final) {
  const StateEstimate e = EstimateOf(kf, cov);
  on_final(e);
  // IMU-rate states to the next keyframe, propagated from this keyframe's final estimate.
  const std::vector<HeldImuSample>& steps = next != nullptr ? next->steps_from_prev : tail;
  Kinematics k{e.x.q_wb, e.x.v_w, e.x.p_wb};
  // Between two keyframes of one standstill the vehicle stands: no IMU wobble in the output either.
  const bool standing = next != nullptr && next->still_from_prev;
  if (standing) k.v.setZero();
  double t = e.x.t;
  for (size_t i = 0; i < steps.size(); ++i) {
    const HeldImuSample& step = steps[i];
    if (!standing) {
      k = ImuStep(k, step.sample.gyro - e.x.bg, step.sample.acc - e.x.ba, earth.g_w, step.dt, nullptr, earth.rate_w);
    }
    t += step.dt;
    if (next != nullptr && i + 1 == steps.size()) break;  // the next keyframe emits itself
    StateEstimate m = e;
    m.x.t = t;
    m.x.q_wb = k.q;
    m.x.v_w = k.v;
    m.x.p_wb = k.p;
    on_final(m);
  }
}

}  // namespace gins
