#include "core/preintegration.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <string>
#include <random>
#include <vector>

#include "core/imu_kernel.h"
#include "core/so3.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kG = 9.81;

// A deterministic, smoothly varying IMU record (true rate and specific force, no bias, no noise).
struct ImuRecord {
  std::vector<Vec3> omega_b, acc_b;
  double dt;
};

ImuRecord MakeVaryingRecord(int n, double dt) {
  ImuRecord rec;
  rec.dt = dt;
  for (int k = 0; k < n; ++k) {
    const double t = k * dt;
    rec.omega_b.push_back(
        Vec3(0.3 * std::sin(2.0 * t), -0.2 + 0.1 * std::cos(3.0 * t), 0.5 * std::sin(0.7 * t + 1.0)));
    rec.acc_b.push_back(Vec3(1.0 + 0.5 * std::cos(1.3 * t), 0.4 * std::sin(2.1 * t), kG + 0.3 * std::sin(t)));
  }
  return rec;
}

NavState MakeState() {
  NavState x;
  x.t = 100.0;
  x.p_wb = Vec3(10.0, -4.0, 2.0);
  x.v_w = Vec3(3.0, 1.0, -0.2);
  x.q_wb = ExpQuat<double>(Vec3(0.1, -0.3, 2.0));
  x.bg = Vec3(0.01, -0.02, 0.005);
  x.ba = Vec3(0.1, 0.05, -0.08);
  return x;
}

// ⊟ between two deltas, in the class's order δp, δv, δθ (b = a ⊞ δ).
Vec9 DeltaMinus(const Preintegration::Delta& b, const Preintegration::Delta& a) {
  Vec9 d;
  d.segment<3>(preint::kP) = b.dp - a.dp;
  d.segment<3>(preint::kV) = b.dv - a.dv;
  d.segment<3>(preint::kTheta) = LogQuat<double>(a.dq.conjugate() * b.dq);
  return d;
}

TEST(PreintegrationTest, PredictEqualsImuStepWithGravity) {
  const ImuRecord rec = MakeVaryingRecord(150, 0.01);
  const NavState x_i = MakeState();
  const Vec3 g_w = GravityWorld(kG);

  // Raw measurements carry x_i's biases; the preintegration is linearised there.
  Preintegration pre(x_i.bg, x_i.ba, 1e-3, 1e-2);
  Kinematics x;
  x.q = x_i.q_wb;
  x.v = x_i.v_w;
  x.p = x_i.p_wb;
  for (size_t k = 0; k < rec.omega_b.size(); ++k) {
    const Vec3 gyro = rec.omega_b[k] + x_i.bg;
    const Vec3 acc = rec.acc_b[k] + x_i.ba;
    pre.Integrate(gyro, acc, rec.dt);
    x = ImuStep(x, gyro - x_i.bg, acc - x_i.ba, g_w, rec.dt);
  }
  const NavState x_j = pre.Predict(x_i, g_w);
  EXPECT_NEAR(pre.dt(), 1.5, 1e-12);
  EXPECT_NEAR(x_j.t, x_i.t + 1.5, 1e-12);
  EXPECT_LT((x_j.p_wb - x.p).norm(), 1e-9);
  EXPECT_LT((x_j.v_w - x.v).norm(), 1e-9);
  EXPECT_LT(LogQuat<double>(x.q.conjugate() * x_j.q_wb).norm(), 1e-9);
  EXPECT_EQ(x_j.bg, x_i.bg);
  EXPECT_EQ(x_j.ba, x_i.ba);
}

// Uniform circular motion, analytic: speed V, yaw rate w, level. Body specific force (0, V·w, g) and rate
// (0, 0, w) are constant, so the kernel (the specific force rotated by the step's mean attitude) converges to
// the truth at O(dt²). The first-order kernel this replaced was 2e-3 m off at 1 kHz.
TEST(PreintegrationTest, PredictsAnalyticCircularMotion) {
  const double V = 10.0, w = 0.3, T = 1.0;
  const Vec3 g_w = GravityWorld(kG);
  NavState x_i;
  x_i.v_w = Vec3(V, 0.0, 0.0);
  const double yaw = w * T;
  const Vec3 p_true = (V / w) * Vec3(std::sin(yaw), 1.0 - std::cos(yaw), 0.0);
  const Vec3 v_true = V * Vec3(std::cos(yaw), std::sin(yaw), 0.0);

  double err_p[2], err_v[2];
  const int rates[2] = {500, 1000};
  for (int r = 0; r < 2; ++r) {
    Preintegration pre(Vec3::Zero(), Vec3::Zero(), 1e-3, 1e-2);
    const double dt = 1.0 / rates[r];
    for (int k = 0; k < rates[r]; ++k) pre.Integrate(Vec3(0.0, 0.0, w), Vec3(0.0, V * w, kG), dt);
    const NavState x_j = pre.Predict(x_i, g_w);
    err_p[r] = (x_j.p_wb - p_true).norm();
    err_v[r] = (x_j.v_w - v_true).norm();
    // Constant rate: the rotation is exact.
    EXPECT_LT(LogQuat<double>(QuatFromYaw(yaw).conjugate() * x_j.q_wb).norm(), 1e-12);
  }
  EXPECT_LT(err_p[1], 1e-7);
  EXPECT_LT(err_v[1], 1e-7);
  // Second order: halving dt quarters the error.
  EXPECT_NEAR(err_p[0] / err_p[1], 4.0, 0.2);
  EXPECT_NEAR(err_v[0] / err_v[1], 4.0, 0.2);
  std::printf("[ circle   ] 1 kHz: |dp| = %.3g m, |dv| = %.3g m/s; 500 Hz / 1 kHz ratio p %.3f v %.3f\n",
              err_p[1], err_v[1], err_p[0] / err_p[1], err_v[0] / err_v[1]);
}

// Covariance of (δp, δv, δθ) against 4000 noisy runs over 1 s at 100 Hz.
TEST(PreintegrationTest, CovarianceMatchesMonteCarlo) {
  const ImuRecord rec = MakeVaryingRecord(100, 0.01);
  const double sigma_g = 0.01, sigma_a = 0.1;  // densities, large enough to matter, small enough to be linear
  const Vec3 bg(0.002, -0.001, 0.003), ba(0.02, -0.03, 0.01);
  Preintegration nominal(bg, ba, sigma_g, sigma_a);
  for (size_t k = 0; k < rec.omega_b.size(); ++k)
    nominal.Integrate(rec.omega_b[k] + bg, rec.acc_b[k] + ba, rec.dt);

  std::mt19937 rng(42);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double sd_g = sigma_g / std::sqrt(rec.dt), sd_a = sigma_a / std::sqrt(rec.dt);
  const int kRuns = 4000;
  Mat9 S = Mat9::Zero();
  Vec9 mean = Vec9::Zero();
  for (int run = 0; run < kRuns; ++run) {
    // The same kernel without Jacobians (a noisy preintegrated delta), to keep the 4000 runs fast.
    Kinematics x;
    for (size_t k = 0; k < rec.omega_b.size(); ++k) {
      const Vec3 eta_g(normal(rng), normal(rng), normal(rng)), eta_a(normal(rng), normal(rng), normal(rng));
      x = ImuStep(x, rec.omega_b[k] + sd_g * eta_g, rec.acc_b[k] + sd_a * eta_a, Vec3::Zero(), rec.dt);
    }
    Preintegration::Delta noisy;
    noisy.dq = x.q;
    noisy.dv = x.v;
    noisy.dp = x.p;
    const Vec9 e = DeltaMinus(noisy, nominal.delta());
    mean += e;
    S += e * e.transpose();
  }
  mean /= kRuns;
  S = S / kRuns - mean * mean.transpose();

  const Mat9& P = nominal.cov();
  // Whitened sample covariance: identity if P is right.
  const Eigen::LLT<Mat9> llt(P);
  ASSERT_EQ(llt.info(), Eigen::Success);
  const Mat9 L_inv = llt.matrixL().solve(Mat9::Identity());
  const Mat9 W = L_inv * S * L_inv.transpose();
  double worst_diag_ratio = 0.0, worst_whitened_diag = 0.0, worst_whitened_off = 0.0;
  for (int i = 0; i < 9; ++i) {
    worst_diag_ratio = std::max(worst_diag_ratio, std::abs(S(i, i) / P(i, i) - 1.0));
    worst_whitened_diag = std::max(worst_whitened_diag, std::abs(W(i, i) - 1.0));
    for (int j = 0; j < 9; ++j) {
      if (i != j) worst_whitened_off = std::max(worst_whitened_off, std::abs(W(i, j)));
    }
  }
  std::printf("[ montecarlo] max |S_ii/P_ii - 1| = %.3f, max |W_ii - 1| = %.3f, max |W_ij| = %.3f\n",
              worst_diag_ratio, worst_whitened_diag, worst_whitened_off);
  EXPECT_LT(worst_diag_ratio, 0.10);
  EXPECT_LT(worst_whitened_diag, 0.10);
  EXPECT_LT(worst_whitened_off, 0.10);
}

// ∂Δ/∂b against central differences of exact re-integration.
TEST(PreintegrationTest, BiasJacobiansMatchReintegration) {
  const ImuRecord rec = MakeVaryingRecord(100, 0.01);
  const Vec3 bg(0.002, -0.001, 0.003), ba(0.02, -0.03, 0.01);
  Preintegration pre(bg, ba, 1e-3, 1e-2);
  for (size_t k = 0; k < rec.omega_b.size(); ++k) pre.Integrate(rec.omega_b[k], rec.acc_b[k], rec.dt);
  const auto f = [&](const Vec6& db) {
    Preintegration p = pre;
    p.Reintegrate(bg + db.head<3>(), ba + db.tail<3>());
    return DeltaMinus(p.delta(), pre.delta());
  };
  const Mat96 J_num = test::NumericJacobian<9, 6>(f, 1e-6);
  const double err = (J_num - pre.bias_jacobian()).norm() / J_num.norm();
  std::printf("[ bias jac ] relative error vs numeric: %.3g\n", err);
  EXPECT_LT(err, 1e-6);
  EXPECT_TRUE((pre.bias_jacobian().block<3, 3>(preint::kTheta, preint::kBa).isZero(0.0)));
}

// First-order bias correction vs re-integration: the error is second order in δb.
TEST(PreintegrationTest, BiasCorrectionIsFirstOrder) {
  const ImuRecord rec = MakeVaryingRecord(100, 0.01);
  const Vec3 bg(0.002, -0.001, 0.003), ba(0.02, -0.03, 0.01);
  Preintegration pre(bg, ba, 1e-3, 1e-2);
  for (size_t k = 0; k < rec.omega_b.size(); ++k) pre.Integrate(rec.omega_b[k], rec.acc_b[k], rec.dt);
  const Vec3 dbg(0.01, -0.02, 0.015), dba(0.1, 0.05, -0.12);

  Vec3 err[2][3];  // [scale][p, v, θ]
  double change = 0.0;
  for (int s = 0; s < 2; ++s) {
    const double scale = s == 0 ? 1.0 : 0.5;
    Preintegration exact = pre;
    exact.Reintegrate(bg + scale * dbg, ba + scale * dba);
    const Vec9 e = DeltaMinus(pre.Corrected(bg + scale * dbg, ba + scale * dba), exact.delta());
    if (s == 0) change = DeltaMinus(exact.delta(), pre.delta()).norm();
    for (int c = 0; c < 3; ++c) err[s][c] = e.segment<3>(3 * c);
  }
  const char* names[3] = {"p", "v", "theta"};
  for (int c = 0; c < 3; ++c) {
    const double ratio = err[0][c].norm() / err[1][c].norm();
    std::printf("[ bias corr] %-5s err(δb) = %.3g, err(δb/2) = %.3g, ratio %.3f\n", names[c],
                err[0][c].norm(), err[1][c].norm(), ratio);
    EXPECT_NEAR(ratio, 4.0, 0.3) << names[c];
  }
  // And it is small against the change it corrects.
  EXPECT_LT((err[0][0].norm() + err[0][1].norm() + err[0][2].norm()) / change, 0.02);
}

// The accelerometer bias enters Δv and Δp linearly (the rotation does not depend on it), so its first-order
// correction equals re-integration to rounding, however large: the smoother re-integrates for the gyro bias
// only (ReintegratedIfMoved).
TEST(PreintegrationTest, AccelerometerBiasCorrectionIsExact) {
  const ImuRecord rec = MakeVaryingRecord(100, 0.01);
  const Vec3 bg(0.002, -0.001, 0.003), ba(0.02, -0.03, 0.01);
  Preintegration pre(bg, ba, 1e-3, 1e-2);
  for (size_t k = 0; k < rec.omega_b.size(); ++k) pre.Integrate(rec.omega_b[k], rec.acc_b[k], rec.dt);
  const Vec3 dba(0.5, 0.3, -0.4);
  Preintegration exact = pre;
  exact.Reintegrate(bg, ba + dba);
  const double change = DeltaMinus(exact.delta(), pre.delta()).norm();
  EXPECT_GT(change, 0.5);
  EXPECT_LT(DeltaMinus(pre.Corrected(bg, ba + dba), exact.delta()).norm(), 1e-12 * (1.0 + change));
}

TEST(PreintegrationTest, ReintegrateAtSameBiasIsIdentityAndZeroDtIsIgnored) {
  const ImuRecord rec = MakeVaryingRecord(50, 0.01);
  Preintegration pre(Vec3(0.01, 0.0, 0.0), Vec3::Zero(), 1e-3, 1e-2);
  for (size_t k = 0; k < rec.omega_b.size(); ++k) {
    pre.Integrate(rec.omega_b[k], rec.acc_b[k], rec.dt);
    pre.Integrate(rec.omega_b[k], rec.acc_b[k], 0.0);
  }
  EXPECT_EQ(pre.num_samples(), 50);
  Preintegration again = pre;
  again.Reintegrate(pre.bg_lin(), pre.ba_lin());
  EXPECT_LT(DeltaMinus(again.delta(), pre.delta()).norm(), 1e-14);
  EXPECT_LT((again.cov() - pre.cov()).norm(), 1e-14 * pre.cov().norm());
  EXPECT_LT((again.bias_jacobian() - pre.bias_jacobian()).norm(), 1e-14);
}

}  // namespace
}  // namespace gins

namespace gins {
namespace GINS_TEST_FILE {

// PredictedCovariance equals the filter's step-by-step propagation of the same error state through the
// kernel's Jacobians (F = [[A, B], [0, I]], the same discrete white noise): both are the linearised model of
// the same steps, so without bias random walk they agree to rounding.
TEST(PredictedCovarianceTest, EqualsStepwisePropagation) {
  const double dt = 0.01, gyro_nd = 2e-3, acc_nd = 2e-2;
  NavState x_i;
  x_i.p_wb = Vec3(1.0, 2.0, 3.0);
  x_i.v_w = Vec3(8.0, -3.0, 0.5);
  x_i.q_wb = ExpQuat<double>(Vec3(0.2, -0.1, 1.1));
  x_i.bg = Vec3(0.01, -0.005, 0.02);
  x_i.ba = Vec3(0.05, 0.02, -0.04);
  Mat15 P_i = Mat15::Zero();
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  for (int r = 0; r < 15; ++r) {
    for (int c = 0; c < 15; ++c) P_i(r, c) = 0.01 * n01(rng);
  }
  P_i = P_i * P_i.transpose() + 1e-4 * Mat15::Identity();

  Preintegration pre(x_i.bg, x_i.ba, gyro_nd, acc_nd);
  Kinematics k{x_i.q_wb, x_i.v_w, x_i.p_wb};
  Mat15 P = P_i;
  const Vec3 g = GravityWorld(9.81);
  for (int s = 0; s < 80; ++s) {
    const double t = s * dt;
    const Vec3 gyro = x_i.bg + Vec3(0.3 * std::sin(2.0 * t), -0.2, 0.5 * std::cos(t));
    const Vec3 acc = x_i.ba + Vec3(1.0 + 0.5 * std::cos(1.3 * t), 0.4 * std::sin(2.1 * t), 9.81);
    pre.Integrate(gyro, acc, dt);
    ImuStepJacobians J;
    k = ImuStep(k, gyro - x_i.bg, acc - x_i.ba, g, dt, &J);
    Mat15 F = Mat15::Identity();
    F.topLeftCorner<9, 9>() = J.A;
    F.block<9, 6>(0, 9) = J.B;
    Mat15 Gq = Mat15::Zero();
    Gq.topLeftCorner<9, 9>() = J.B * ImuDiscreteNoise(gyro_nd, acc_nd, dt) * J.B.transpose();
    P = F * P * F.transpose() + Gq;
  }
  const Mat15 P_pred = PredictedCovariance(x_i, P_i, pre, 0.0, 0.0);
  EXPECT_LT((P_pred - P).cwiseAbs().maxCoeff(), 1e-12 * P.cwiseAbs().maxCoeff());
  // The bias random walks add σ²·Δt to the bias block.
  const Mat15 P_rw = PredictedCovariance(x_i, P_i, pre, 1e-4, 1e-3);
  EXPECT_NEAR(P_rw(9, 9) - P_pred(9, 9), 1e-8 * 0.8, 1e-15);
  EXPECT_NEAR(P_rw(14, 14) - P_pred(14, 14), 1e-6 * 0.8, 1e-13);
  // And the predicted mean is the kernel's.
  const NavState x_j = pre.Predict(x_i, g);
  EXPECT_LT((x_j.p_wb - k.p).norm(), 1e-9);
}

// A guessed step across an IMU gap (IntegrateGuess) has a full-rank covariance: the held error alone moves δp
// and δv together, leaving three empty directions that a factor's square-root information would pin. Its
// velocity variance is the held error's plus the white part's, 2·σ²·dt² per axis, and a gap of one step or of
// several steps alike leaves every eigenvalue far above the 1e-12 floor.
TEST(Preintegration, GuessedStepAcrossAGapHasAFullRankCovariance) {
  const double sigma_a = 2.0, sigma_g = 0.17;
  for (int steps : {1, 3}) {
    for (double dt : {0.6, 1.0, 30.0}) {
      SCOPED_TRACE("steps " + std::to_string(steps) + ", dt " + std::to_string(dt));
      Preintegration p(Vec3::Zero(), Vec3::Zero(), 2e-4, 1e-3);
      for (int k = 0; k < steps; ++k) p.IntegrateGuess(Vec3::Zero(), Vec3(0.0, 0.0, kG), dt / steps, sigma_g, sigma_a);
      const Eigen::SelfAdjointEigenSolver<Mat9> es(p.cov());
      const Vec9 lambda = es.eigenvalues();
      EXPECT_GT(lambda.minCoeff(), 1e-9 * lambda.maxCoeff()) << lambda.transpose();
      if (steps == 1) {
        EXPECT_NEAR(p.cov()(preint::kV, preint::kV), 2.0 * sigma_a * sigma_a * dt * dt, 1e-5 * dt * dt);
      }
    }
  }
  // An ordinary step keeps the sensor's own model (no white part added): the accelerometer's noise, and the
  // gyro's through the sculling term (½dt²·g per rad/s of rate about a horizontal axis).
  Preintegration q(Vec3::Zero(), Vec3::Zero(), 2e-4, 1e-3);
  const double dt = 0.01, sculling = 0.5 * dt * dt * kG;
  q.Integrate(Vec3::Zero(), Vec3(0.0, 0.0, kG), dt);
  EXPECT_NEAR(q.cov()(preint::kV, preint::kV), 1e-6 * dt + sculling * sculling * 4e-8 / dt, 1e-18);
}

}  // namespace
}  // namespace gins
