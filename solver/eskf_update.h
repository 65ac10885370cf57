// The ESKF's one measurement update. A measurement model supplies its residual and its Jacobian per block of
// the error state it touches (OpenVINS' H_order idea); EmbedJacobian places those columns in the full-width
// H by the layout (solver/eskf_state.h), and GatedUpdate runs the χ²-gated Joseph-form update.
#pragma once

#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <initializer_list>

#include "solver/eskf_state.h"
#include "solver/estimator.h"
#include "solver/estimator_common.h"

namespace gins {
namespace eskf {

// ∂r/∂δx_block: M rows, Dim(block) columns. Fixed capacity, so no allocation at measurement rate (Eigen
// wants a one-row matrix row-major).
template <int M>
struct BlockJacobian {
  using Matrix = Eigen::Matrix<double, M, Eigen::Dynamic, (M == 1 ? Eigen::RowMajor : Eigen::ColMajor), M,
                               kMaxBlockDim>;
  Block block;
  Matrix H;
};

// The full-width Jacobian: each block's columns at its offset, zero for the blocks not listed. A block
// listed twice or with the wrong number of columns is a programming error.
template <int M>
Eigen::Matrix<double, M, kDim> EmbedJacobian(std::initializer_list<BlockJacobian<M>> blocks) {
  static_assert(kNumBlocks <= 32, "the seen-mask is 32 bits");
  Eigen::Matrix<double, M, kDim> H = Eigen::Matrix<double, M, kDim>::Zero();
  uint32_t seen = 0;
  for (const BlockJacobian<M>& j : blocks) {
    const int b = static_cast<int>(j.block);
    CHECK(b >= 0 && b < kNumBlocks) << "no such block " << b;
    CHECK(!(seen & (1u << b))) << "block " << kBlocks[b].name << " listed twice";
    CHECK_EQ(j.H.cols(), kBlocks[b].dim) << "Jacobian columns for block " << kBlocks[b].name;
    seen |= 1u << b;
    H.middleCols(Offset(j.block), kBlocks[b].dim) = j.H;
  }
  return H;
}

// Gated Kalman update of the covariance P (N×N) with residual r = h(x) − z, Jacobian H and noise R. When
// S = HPHᵀ + R is positive definite, r finite and rᵀS⁻¹r ≤ gate: P becomes the Joseph-form posterior,
// *dx = −Kr (the correction to inject), counts->used grows, and it returns true. Otherwise P and *dx are
// left, the rejection is counted ("numerical" or "chi2_gate") at time t, and it returns false.
template <int M, int N>
bool GatedUpdate(const Eigen::Matrix<double, M, 1>& r, const Eigen::Matrix<double, M, N>& H,
                 const Eigen::Matrix<double, M, M>& R, double gate, double t, MeasurementCounts* counts,
                 Eigen::Matrix<double, N, N>* P, Eigen::Matrix<double, N, 1>* dx) {
  const Eigen::Matrix<double, N, M> PHt = P->lazyProduct(H.transpose());
  const Eigen::Matrix<double, M, M> S = H.lazyProduct(PHt) + R;
  const Eigen::LLT<Eigen::Matrix<double, M, M>> llt(S);
  if (llt.info() != Eigen::Success || !r.allFinite()) {
    counts->Reject("numerical", t);
    return false;
  }
  const double chi2 = r.dot(llt.solve(r));
  if (!(chi2 <= gate)) {  // a NaN χ² is rejected too
    counts->Reject("chi2_gate", t);
    return false;
  }
  const Eigen::Matrix<double, N, M> K = llt.solve(PHt.transpose()).transpose();
  *dx = -K * r;
  // Joseph form, (I−KH)P(I−KH)ᵀ + KRKᵀ, which keeps P symmetric and positive for any gain, expanded as
  // P − K(PHᵀ)ᵀ − PHᵀKᵀ + KSKᵀ: rank-M products instead of three N×N ones.
  const Eigen::Matrix<double, N, M> KS = K.lazyProduct(S);
  const Eigen::Matrix<double, N, N> KHP = K.lazyProduct(PHt.transpose());
  *P += KS.lazyProduct(K.transpose()) - KHP - KHP.transpose();
  ++counts->used;
  return true;
}

}  // namespace eskf
}  // namespace gins
