// The ESKF's one measurement update (solver/eskf_update.h) against the textbook Kalman update, and its gate.
#include "solver/eskf_update.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "core/chi2.h"

namespace gins::eskf {
namespace GINS_TEST_FILE {

template <int N>
Eigen::Matrix<double, N, N> RandomSpd(std::mt19937* rng, double min_eig) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, N, N> A;
  for (int i = 0; i < N * N; ++i) A(i) = n(*rng);
  return A * A.transpose() / N + min_eig * Eigen::Matrix<double, N, N>::Identity();
}

template <int R, int C>
Eigen::Matrix<double, R, C> RandomMat(std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, R, C> A;
  for (int i = 0; i < R * C; ++i) A(i) = n(*rng);
  return A;
}

// K = PHᵀS⁻¹, dx = −Kr, P⁺ = (I−KH)P(I−KH)ᵀ + KRKᵀ, with dense inverses: the textbook form.
struct Textbook {
  MatX P;
  VecX dx;
};
Textbook TextbookUpdate(const MatX& P, const MatX& H, const MatX& R, const VecX& r) {
  const MatX S = H * P * H.transpose() + R;
  const MatX K = P * H.transpose() * S.inverse();
  const MatX IKH = MatX::Identity(P.rows(), P.cols()) - K * H;
  return {IKH * P * IKH.transpose() + K * R * K.transpose(), -K * r};
}

template <int M, int N>
void ExpectTextbook(std::mt19937* rng) {
  const Eigen::Matrix<double, N, N> P0 = RandomSpd<N>(rng, 0.1);
  const Eigen::Matrix<double, M, N> H = RandomMat<M, N>(rng);
  const Eigen::Matrix<double, M, M> R = RandomSpd<M>(rng, 0.05);
  const Eigen::Matrix<double, M, 1> r = RandomMat<M, 1>(rng);
  Eigen::Matrix<double, N, N> P = P0;
  Eigen::Matrix<double, N, 1> dx;
  MeasurementCounts counts;
  ASSERT_TRUE((GatedUpdate<M, N>(r, H, R, std::numeric_limits<double>::infinity(), 1.0, &counts, &P, &dx)));
  const Textbook want = TextbookUpdate(P0, H, R, r);
  EXPECT_LT((P - want.P).cwiseAbs().maxCoeff(), 1e-12) << "M=" << M << " N=" << N;
  EXPECT_LT((dx - want.dx).cwiseAbs().maxCoeff(), 1e-12) << "M=" << M << " N=" << N;
  EXPECT_EQ(counts.used, 1u);
  EXPECT_TRUE(counts.rejected.empty());
}

TEST(EskfGatedUpdate, EqualsTextbookKalmanUpdate) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    ExpectTextbook<1, 2>(&rng);
    ExpectTextbook<2, 4>(&rng);
    ExpectTextbook<3, kDim>(&rng);
  }
}

TEST(EskfGatedUpdate, EmbeddedJacobianEqualsTextbookOnTheFullState) {
  // A GNSS-like measurement of (δp, δθ) on the full layout, by its blocks.
  std::mt19937 rng(11);
  const Eigen::Matrix<double, kDim, kDim> P0 = RandomSpd<kDim>(&rng, 0.1);
  const Mat3 H_p = Mat3::Identity() + 0.1 * RandomMat<3, 3>(&rng);
  const Mat3 H_theta = RandomMat<3, 3>(&rng);
  const Eigen::Matrix<double, 3, kDim> H = EmbedJacobian<3>({{Block::kP, H_p}, {Block::kTheta, H_theta}});
  MatX H_dense = MatX::Zero(3, kDim);
  H_dense.block(0, 0, 3, 3) = H_p;
  H_dense.block(0, 6, 3, 3) = H_theta;
  const Mat3 R = Vec3(0.02, 0.03, 0.05).cwiseAbs2().asDiagonal();
  const Vec3 r(0.1, -0.2, 0.05);
  Eigen::Matrix<double, kDim, kDim> P = P0;
  Eigen::Matrix<double, kDim, 1> dx;
  MeasurementCounts counts;
  ASSERT_TRUE((GatedUpdate<3, kDim>(r, H, R, 1e9, 0.0, &counts, &P, &dx)));
  const Textbook want = TextbookUpdate(P0, H_dense, R, r);
  EXPECT_LT((P - want.P).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((dx - want.dx).cwiseAbs().maxCoeff(), 1e-12);
}

// The residual along a direction scaled so that rᵀS⁻¹r is the given value.
Eigen::Vector2d ResidualWithChi2(const Eigen::Matrix2d& S, double chi2) {
  const Eigen::Vector2d d(1.0, -0.5);
  return d * std::sqrt(chi2 / d.dot(S.inverse() * d));
}

TEST(EskfGatedUpdate, Chi2GateRejectsOutliersOnly) {
  std::mt19937 rng(3);
  const Eigen::Matrix<double, 4, 4> P0 = RandomSpd<4>(&rng, 0.1);
  const Eigen::Matrix<double, 2, 4> H = RandomMat<2, 4>(&rng);
  const Eigen::Matrix2d R = Eigen::Matrix2d::Identity() * 0.01;
  const Eigen::Matrix2d S = H * P0 * H.transpose() + R;
  const double gate = Chi2Quantile(0.99, 2);
  MeasurementCounts counts;

  Eigen::Matrix<double, 4, 4> P = P0;
  Eigen::Matrix<double, 4, 1> dx = Eigen::Matrix<double, 4, 1>::Constant(42.0);
  EXPECT_FALSE((GatedUpdate<2, 4>(ResidualWithChi2(S, 1.01 * gate), H, R, gate, 5.0, &counts, &P, &dx)));
  EXPECT_EQ(P, P0);  // a rejected measurement changes nothing
  EXPECT_EQ(dx, (Eigen::Matrix<double, 4, 1>::Constant(42.0)));
  EXPECT_EQ(counts.used, 0u);
  EXPECT_EQ(counts.rejected["chi2_gate"], 1u);
  ASSERT_EQ(counts.rejected_times.size(), 1u);
  EXPECT_EQ(counts.rejected_times[0], 5.0);

  EXPECT_TRUE((GatedUpdate<2, 4>(ResidualWithChi2(S, 0.99 * gate), H, R, gate, 6.0, &counts, &P, &dx)));
  EXPECT_NE(P, P0);
  EXPECT_EQ(counts.used, 1u);
  EXPECT_EQ(counts.rejected["chi2_gate"], 1u);
}

TEST(EskfGatedUpdate, NumericalFailuresAreRejected) {
  std::mt19937 rng(5);
  const Eigen::Matrix<double, 3, 3> P0 = RandomSpd<3>(&rng, 0.1);
  const Eigen::Matrix<double, 2, 3> H = RandomMat<2, 3>(&rng);
  Eigen::Matrix<double, 3, 3> P = P0;
  Eigen::Matrix<double, 3, 1> dx;
  MeasurementCounts counts;
  const double inf = std::numeric_limits<double>::infinity();
  // A non-finite residual.
  const Eigen::Vector2d bad(std::nan(""), 0.0);
  EXPECT_FALSE((GatedUpdate<2, 3>(bad, H, Eigen::Matrix2d::Identity(), inf, 1.0, &counts, &P, &dx)));
  // S not positive definite (R negative enough).
  EXPECT_FALSE((GatedUpdate<2, 3>(Eigen::Vector2d::Zero(), H, Eigen::Matrix2d::Identity() * -1e6, inf, 2.0,
                                  &counts, &P, &dx)));
  EXPECT_EQ(counts.rejected["numerical"], 2u);
  EXPECT_EQ(counts.used, 0u);
  EXPECT_EQ(P, P0);
}

}  // namespace
}  // namespace gins::eskf
