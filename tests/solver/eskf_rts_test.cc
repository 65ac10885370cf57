// The RTS backward step (solver/eskf_rts.h) against the textbook smoother on a linear model: the smoothed
// means and covariances of a Kalman filter + RtsBackwardStep equal the batch least-squares solution (the
// normal equations of all states at once, inverted densely: the definition of the smoothed estimate).
#include "solver/eskf_rts.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace gins {
namespace GINS_TEST_FILE {

// A 1-D constant-velocity target (position, velocity) with white acceleration, position fixes, and a
// run of epochs without a fix (an outage) in the middle.
TEST(RtsBackwardStep, EqualsTheBatchSolutionOnALinearModel) {
  constexpr int N = 2;
  using Mat = Eigen::Matrix<double, N, N>;
  using Vec = Eigen::Matrix<double, N, 1>;
  const int K = 40;
  const double dt = 0.5, q = 0.3, r = 0.8;
  Mat Phi;
  Phi << 1.0, dt, 0.0, 1.0;
  Mat Q;
  Q << q * dt * dt * dt / 3.0, q * dt * dt / 2.0, q * dt * dt / 2.0, q * dt;
  const Eigen::Matrix<double, 1, N> H(1.0, 0.0);
  const Vec x0(0.0, 1.0);
  Mat P0;
  P0 << 4.0, 0.0, 0.0, 1.0;
  std::mt19937 rng(11);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<bool> has_fix(K);
  std::vector<double> z(K);
  Vec truth = x0;
  for (int k = 0; k < K; ++k) {
    if (k > 0) truth = Phi * truth + Eigen::LLT<Mat>(Q).matrixL() * Vec(unit(rng), unit(rng));
    has_fix[k] = !(k >= 15 && k < 27);
    z[k] = truth[0] + std::sqrt(r) * unit(rng);
  }

  // Forward filter, keeping what the backward pass needs.
  std::vector<Vec> x_prior(K), x_post(K);
  std::vector<Mat> P_prior(K), P_post(K);
  for (int k = 0; k < K; ++k) {
    x_prior[k] = k == 0 ? x0 : Vec(Phi * x_post[k - 1]);
    P_prior[k] = k == 0 ? P0 : Mat(Phi * P_post[k - 1] * Phi.transpose() + Q);
    x_post[k] = x_prior[k];
    P_post[k] = P_prior[k];
    if (has_fix[k]) {
      const double S = (H * P_prior[k] * H.transpose())(0, 0) + r;
      const Vec Kg = P_prior[k] * H.transpose() / S;
      x_post[k] = x_prior[k] + Kg * (z[k] - (H * x_prior[k])(0, 0));
      P_post[k] = (Mat::Identity() - Kg * H) * P_prior[k];
    }
  }
  // Backward.
  std::vector<Vec> x_s(K);
  std::vector<Mat> P_s(K);
  x_s[K - 1] = x_post[K - 1];
  P_s[K - 1] = P_post[K - 1];
  for (int k = K - 2; k >= 0; --k) {
    Vec delta;
    ASSERT_TRUE(RtsBackwardStep<N>(P_post[k], Phi, P_prior[k + 1], Vec(x_s[k + 1] - x_prior[k + 1]), P_s[k + 1],
                                   &delta, &P_s[k]));
    x_s[k] = x_post[k] + delta;
  }

  // The batch: minimise |x_0 − x0|²_P0 + Σ|x_{k+1} − Φx_k|²_Q + Σ|z_k − Hx_k|²_r over all states.
  const int n = N * K;
  MatX A = MatX::Zero(n, n);
  VecX b = VecX::Zero(n);
  const Mat P0i = P0.inverse(), Qi = Q.inverse();
  A.block<N, N>(0, 0) += P0i;
  b.segment<N>(0) += P0i * x0;
  for (int k = 0; k + 1 < K; ++k) {
    // r = x_{k+1} − Φ x_k: J = [−Φ, I].
    Eigen::Matrix<double, N, 2 * N> J;
    J << -Phi, Mat::Identity();
    A.block<2 * N, 2 * N>(N * k, N * k) += J.transpose() * Qi * J;
  }
  for (int k = 0; k < K; ++k) {
    if (!has_fix[k]) continue;
    A.block<N, N>(N * k, N * k) += H.transpose() * H / r;
    b.segment<N>(N * k) += H.transpose() * z[k] / r;
  }
  const MatX cov = A.inverse();
  const VecX x_batch = cov * b;
  double worst_x = 0.0, worst_P = 0.0;
  for (int k = 0; k < K; ++k) {
    worst_x = std::max(worst_x, (x_s[k] - x_batch.segment<N>(N * k)).cwiseAbs().maxCoeff());
    worst_P = std::max(worst_P, (P_s[k] - cov.block<N, N>(N * k, N * k)).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst_x, 1e-9);
  EXPECT_LT(worst_P, 1e-9);
  // The outage is where smoothing matters: the smoothed σ mid-outage is well below the filtered one.
  EXPECT_LT(P_s[20](0, 0), 0.5 * P_post[20](0, 0));
}

// A singular predicted covariance (a state nobody estimates) is reported, not inverted.
TEST(RtsBackwardStep, RefusesASingularPrediction) {
  using Mat = Eigen::Matrix<double, 2, 2>;
  using Vec = Eigen::Matrix<double, 2, 1>;
  Mat P = Mat::Identity(), Phi = Mat::Identity(), P_prior = Mat::Zero();
  P_prior(0, 0) = 1.0;
  Vec delta;
  Mat P_s;
  EXPECT_FALSE(RtsBackwardStep<2>(P, Phi, P_prior, Vec::Zero(), P_prior, &delta, &P_s));
}

}  // namespace
}  // namespace gins
