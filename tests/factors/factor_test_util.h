// Helpers shared by the factor tests: random poses, a GradientChecker wrapper and an analytic-vs-oracle check.
#pragma once

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/conventions.h"
#include "core/imu_kernel.h"
#include "core/preintegration.h"
#include "core/so3.h"
#include "factors/pose_manifold.h"
#include "test_util.h"

namespace gins::test {

inline Vec3 RandomVec3(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0.0, scale);
  return Vec3(n(rng), n(rng), n(rng));
}

using PoseBlock = std::array<double, 7>;

inline PoseBlock MakePose(const Vec3& p_wb, const Quat& q_wb) {
  PoseBlock x;
  SetPose(p_wb, q_wb.normalized(), x.data());
  return x;
}

inline PoseBlock RandomPose(std::mt19937& rng) {
  return MakePose(RandomVec3(rng, 10.0), ExpQuat<double>(RandomVec3(rng, 1.0)));
}

// A square-root information of a raw GNSS constraint (factors/raw_gnss_factor.h) of the given rank: its
// rows past the rank zero, the directions the satellites do not see.
inline Mat3 SqrtInfoOfRank(int rank) {
  Mat3 s;
  s << 2.0, -0.5, 0.3, 0.1, 1.5, -0.7, 0.4, 0.2, 0.9;
  s.bottomRows(3 - rank).setZero();
  return s;
}

// Pose x ⊞ δ (PoseManifold::Plus).
inline PoseBlock PosePlus(const PoseBlock& x, const Vec6& delta) {
  PoseBlock y;
  PoseManifold().Plus(x.data(), delta.data(), y.data());
  return y;
}

// A pose near x: x ⊞ (δp, δθ), each component drawn with σ sigma_p (m) and sigma_theta (rad), δp first.
inline PoseBlock RandomPoseNear(std::mt19937& rng, const PoseBlock& x, double sigma_p, double sigma_theta) {
  Vec6 d;
  d.head<3>() = RandomVec3(rng, sigma_p);
  d.tail<3>() = RandomVec3(rng, sigma_theta);
  return PosePlus(x, d);
}

// Two cost functions of the same residual (an analytic one and its autodiff oracle) agree at `parameters`:
// residuals to 1e-9·(1 + |r|); each block's Jacobian in the tangent (a manifold block's ambient Jacobian
// times its PlusJacobian: ambient Jacobians may differ along directions Ceres never uses) to 1e-9 of its norm,
// a Euclidean block's to 1e-9·(1 + its norm).
inline void ExpectSameResidualAndJacobians(const ceres::CostFunction& a, const ceres::CostFunction& b,
                                           const std::vector<const ceres::Manifold*>& manifolds,
                                           const std::vector<const double*>& parameters, const std::string& what) {
  using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const int m = a.num_residuals();
  const std::vector<int32_t>& sizes = a.parameter_block_sizes();
  Eigen::VectorXd r_a(m), r_b(m);
  std::vector<RowMat> J_a, J_b;
  std::vector<double*> ptr_a, ptr_b;
  for (int32_t size : sizes) {
    J_a.emplace_back(m, size);
    J_b.emplace_back(m, size);
  }
  for (size_t k = 0; k < sizes.size(); ++k) {
    ptr_a.push_back(J_a[k].data());
    ptr_b.push_back(J_b[k].data());
  }
  ASSERT_TRUE(a.Evaluate(parameters.data(), r_a.data(), ptr_a.data())) << what;
  ASSERT_TRUE(b.Evaluate(parameters.data(), r_b.data(), ptr_b.data())) << what;
  EXPECT_LT((r_a - r_b).norm(), 1e-9 * (1.0 + r_b.norm())) << what;
  for (size_t k = 0; k < sizes.size(); ++k) {
    if (manifolds[k] == nullptr) {
      EXPECT_LT((J_a[k] - J_b[k]).norm(), 1e-9 * (1.0 + J_b[k].norm())) << what << ", block " << k;
      continue;
    }
    RowMat lift(sizes[k], manifolds[k]->TangentSize());
    ASSERT_TRUE(manifolds[k]->PlusJacobian(parameters[k], lift.data())) << what;
    const RowMat t_a = J_a[k] * lift, t_b = J_b[k] * lift;
    EXPECT_LT((t_a - t_b).norm(), 1e-9 * t_b.norm()) << what << ", block " << k;
  }
}

// Probes cost's Jacobians in tangent space (manifold per block, nullptr = Euclidean) with
// ceres::GradientChecker (Ridders differences through the same manifolds) and returns the worst entry error
//   |J_user − J_numeric| / max(|J_user|, |J_numeric|, 1e-6·(largest entry of that residual row)).
// The row floor keeps analytically-zero entries (user 1e-17, numeric 1e-14) from counting as a relative
// error of 1, which GradientChecker's own verdict does. Expects the worst error below relative_precision.
inline double CheckJacobians(const ceres::CostFunction& cost,
                             const std::vector<const ceres::Manifold*>& manifolds,
                             const std::vector<const double*>& parameters, double relative_precision,
                             const std::string& what) {
  ceres::NumericDiffOptions options;
  // Ridders' default first step (1e-2 of each ambient coordinate) is too coarse around atan2 (heading);
  // 1e-4 is what ceres/manifold_test_utils.h uses.
  options.ridders_relative_initial_step_size = 1e-4;
  ceres::GradientChecker checker(&cost, &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(parameters.data(), relative_precision, &results);
  EXPECT_TRUE(results.return_value) << what << ": evaluation failed";
  if (!results.return_value) return 1.0;
  const int num_rows = cost.num_residuals();
  Eigen::VectorXd row_max = Eigen::VectorXd::Zero(num_rows);
  for (const auto& J : results.local_numeric_jacobians) {
    for (int i = 0; i < num_rows; ++i) row_max[i] = std::max(row_max[i], J.row(i).cwiseAbs().maxCoeff());
  }
  double worst = 0.0;
  for (size_t k = 0; k < results.local_jacobians.size(); ++k) {
    const Eigen::MatrixXd& J_user = results.local_jacobians[k];
    const Eigen::MatrixXd& J_num = results.local_numeric_jacobians[k];
    for (int i = 0; i < J_user.rows(); ++i) {
      for (int j = 0; j < J_user.cols(); ++j) {
        const double scale =
            std::max({std::abs(J_user(i, j)), std::abs(J_num(i, j)), 1e-6 * row_max[i], 1e-300});
        worst = std::max(worst, std::abs(J_user(i, j) - J_num(i, j)) / scale);
      }
    }
  }
  EXPECT_LT(worst, relative_precision) << what << "\n" << results.error_log;
  return worst;
}

// 0.7 s of a turning, accelerating body preintegrated from keyframe i, its biases off zero: the interval
// of the attached factors' Jacobian tests.
struct AttachedInterval {
  std::shared_ptr<Preintegration> preint;
  ImuEarthTerms earth;
  PoseBlock pose_i;
  Vec3 vel_i;
  Vec6 bias;
};

inline AttachedInterval MakeAttachedInterval(const Vec3& rate_w) {
  AttachedInterval s;
  s.earth.g_w = GravityWorld(9.81);
  s.earth.rate_w = rate_w;
  s.bias << 0.01, -0.02, 0.005, 0.1, 0.05, -0.08;
  s.pose_i = MakePose(Vec3(12.0, 4.0, -0.2), ExpQuat<double>(Vec3(0.1, -0.3, 2.0)));
  s.vel_i = Vec3(10.0, -4.0, 2.0);
  s.preint = std::make_shared<Preintegration>(s.bias.head<3>(), s.bias.tail<3>(), 2e-3, 2e-2);
  for (int k = 0; k < 70; ++k) {
    const double t = k * 0.01;
    const Vec3 omega(0.3 * std::sin(2.0 * t), -0.2, 0.5 * std::sin(0.7 * t + 1.0));
    const Vec3 acc(1.0 + 0.5 * std::cos(1.3 * t), 0.4, 9.81 + 0.3 * std::sin(t));
    s.preint->Integrate(omega + s.bias.head<3>(), acc + s.bias.tail<3>(), 0.01);
  }
  return s;
}

// Keyframe i's blocks away from where the interval starts (and its biases away from their linearisation
// point, so the first-order bias correction matters).
struct AttachedBlocks {
  PoseBlock pose;
  Vec3 vel;
  Vec6 bias;
};

inline AttachedBlocks PerturbedBlocks(std::mt19937& rng, const PoseBlock& pose_i, const Vec3& vel_i,
                                      const Vec6& bias) {
  AttachedBlocks b;
  b.pose = RandomPoseNear(rng, pose_i, 1.0, 0.3);
  b.vel = vel_i + RandomVec3(rng, 1.0);
  b.bias = bias;
  b.bias.head<3>() += RandomVec3(rng, 0.02);
  b.bias.tail<3>() += RandomVec3(rng, 0.2);
  return b;
}

}  // namespace gins::test
