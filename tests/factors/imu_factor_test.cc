#include "factors/imu_factor.h"

#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/imu_kernel.h"
#include "core/preintegration.h"
#include "factor_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kG = 9.81;

// Truth: states i and j joined by noise-free IMU data stepped through the kernel with gravity (exactly the
// scheme the preintegration uses), raw samples carrying the true biases.
struct ImuScenario {
  test::PoseBlock pose_i, pose_j;
  Vec3 vel_i, vel_j;
  Vec6 bias;  // bg, ba (true, constant over the interval)
  std::shared_ptr<Preintegration> preint;
};

ImuScenario MakeScenario(int num_samples, double dt, const Vec6& bias_lin_offset) {
  ImuScenario s;
  s.bias << 0.01, -0.02, 0.005, 0.1, 0.05, -0.08;
  Kinematics x;
  x.p = Vec3(10.0, -4.0, 2.0);
  x.v = Vec3(3.0, 1.0, -0.2);
  x.q = ExpQuat<double>(Vec3(0.1, -0.3, 2.0));
  s.pose_i = test::MakePose(x.p, x.q);
  s.vel_i = x.v;
  const Vec6 bias_lin = s.bias + bias_lin_offset;
  s.preint = std::make_shared<Preintegration>(bias_lin.head<3>(), bias_lin.tail<3>(), 2e-3, 2e-2);
  for (int k = 0; k < num_samples; ++k) {
    const double t = k * dt;
    const Vec3 omega(0.3 * std::sin(2.0 * t), -0.2 + 0.1 * std::cos(3.0 * t), 0.5 * std::sin(0.7 * t + 1.0));
    const Vec3 acc(1.0 + 0.5 * std::cos(1.3 * t), 0.4 * std::sin(2.1 * t), kG + 0.3 * std::sin(t));
    s.preint->Integrate(omega + s.bias.head<3>(), acc + s.bias.tail<3>(), dt);
    x = ImuStep(x, omega, acc, GravityWorld(kG), dt);
  }
  s.pose_j = test::MakePose(x.p, x.q);
  s.vel_j = x.v;
  return s;
}

std::vector<const ceres::Manifold*> ImuManifolds(const PoseManifold* m) {
  return {m, nullptr, nullptr, m, nullptr};
}

TEST(ImuFactorTest, ResidualIsZeroAtTruth) {
  const ImuScenario s = MakeScenario(100, 0.01, Vec6::Zero());
  const ImuFactor factor(s.preint, GravityWorld(kG));
  Vec9 r;
  ASSERT_TRUE(
      factor(s.pose_i.data(), s.vel_i.data(), s.bias.data(), s.pose_j.data(), s.vel_j.data(), r.data()));
  // Unwhiten to report in m, m/s, rad.
  const Vec9 r_raw = factor.sqrt_information().inverse() * r;
  std::printf("[ imu truth] |r_p| = %.2g m, |r_v| = %.2g m/s, |r_θ| = %.2g rad, |r_whitened| = %.2g\n",
              r_raw.segment<3>(preint::kP).norm(), r_raw.segment<3>(preint::kV).norm(),
              r_raw.segment<3>(preint::kTheta).norm(), r.norm());
  EXPECT_LT(r_raw.norm(), 1e-9);
  EXPECT_LT(r.norm(), 1e-6);
  // Whitening: SᵀS = Σ⁻¹.
  const Mat9& S = factor.sqrt_information();
  EXPECT_LT((S.transpose() * S * s.preint->cov() - Mat9::Identity()).norm(), 1e-8);
}

TEST(ImuFactorTest, ResidualWithBiasCorrectionAtTruth) {
  // Linearised away from the true bias: the residual at truth is the second-order remainder, small.
  Vec6 offset;
  offset << 1e-3, -2e-3, 1e-3, 1e-2, -1e-2, 2e-2;
  const ImuScenario s = MakeScenario(100, 0.01, offset);
  const ImuFactor factor(s.preint, GravityWorld(kG));
  Vec9 r;
  factor(s.pose_i.data(), s.vel_i.data(), s.bias.data(), s.pose_j.data(), s.vel_j.data(), r.data());
  const Vec9 r_raw = factor.sqrt_information().inverse() * r;
  std::printf("[ imu bias ] residual at truth with δb ≠ 0: |r_raw| = %.2g, |r_whitened| = %.2g\n",
              r_raw.norm(), r.norm());
  EXPECT_LT(r_raw.norm(), 1e-4);
}

// A set of evaluation points for comparing the analytic and autodiff cost functions.
struct ProbePoint {
  std::string name;
  std::shared_ptr<const Preintegration> preint;
  test::PoseBlock pose_i, pose_j;
  Vec3 vel_i, vel_j;
  Vec6 bias;
  std::vector<const double*> params() const {
    return {pose_i.data(), vel_i.data(), bias.data(), pose_j.data(), vel_j.data()};
  }
};

// Scenarios: intervals from one sample to 10 s (ΔR of several radians), biases at and far from the
// linearisation point; at each, the truth, random points (rotation errors ~1 rad, velocity errors ~1 m/s,
// bias errors) and a point whose quaternions are given as −q.
std::vector<ProbePoint> ProbePoints() {
  struct Config {
    std::string name;
    int num_samples;
    double dt;
    Vec6 bias_lin_offset;
  };
  Vec6 small, large;
  small << 1e-3, -2e-3, 1e-3, 1e-2, -1e-2, 2e-2;
  large << 0.05, -0.04, 0.06, 0.5, -0.4, 0.3;
  const std::vector<Config> configs = {{"100 x 10 ms, small db", 100, 0.01, small},
                                       {"100 x 10 ms, db = 0", 100, 0.01, Vec6::Zero()},
                                       {"1000 x 10 ms, large db", 1000, 0.01, large},
                                       {"400 x 5 ms, large db", 400, 0.005, large},
                                       {"3 x 5 ms, small db", 3, 0.005, small},
                                       {"1 x 10 ms (one sample), large db", 1, 0.01, large}};
  std::vector<ProbePoint> points;
  std::mt19937 rng(11);
  for (const Config& c : configs) {
    const ImuScenario s = MakeScenario(c.num_samples, c.dt, c.bias_lin_offset);
    ProbePoint truth{c.name + ", truth", s.preint, s.pose_i, s.pose_j, s.vel_i, s.vel_j, s.bias};
    points.push_back(truth);
    for (int trial = 0; trial < 4; ++trial) {
      ProbePoint p = truth;
      p.name = c.name + ", random " + std::to_string(trial);
      Vec6 d_i, d_j;
      d_i << test::RandomVec3(rng, 1.0), test::RandomVec3(rng, 0.5);
      d_j << test::RandomVec3(rng, 1.0), test::RandomVec3(rng, 0.5);
      p.pose_i = test::PosePlus(s.pose_i, d_i);
      p.pose_j = test::PosePlus(s.pose_j, d_j);
      p.vel_i += test::RandomVec3(rng, 1.0);
      p.vel_j += test::RandomVec3(rng, 1.0);
      p.bias.head<3>() += test::RandomVec3(rng, 0.03);
      p.bias.tail<3>() += test::RandomVec3(rng, 0.3);
      points.push_back(p);
    }
    ProbePoint flipped = points.back();
    flipped.name = c.name + ", -q";
    for (int k = pose::kQ; k < pose::kAmbient; ++k) {
      flipped.pose_i[k] = -flipped.pose_i[k];
      flipped.pose_j[k] = -flipped.pose_j[k];
    }
    points.push_back(flipped);
  }
  return points;
}

struct Evaluation {
  Vec9 r;
  std::vector<MatX> J_amb;  // 9 × ambient size, per block
  std::vector<MatX> J_tan;  // 9 × tangent size (ambient × PlusJacobian for the poses)
};

Evaluation EvaluateWithJacobians(const ceres::CostFunction& cost, const ProbePoint& p) {
  using RowMajorMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
  std::vector<RowMajorMat> J(sizes.size());
  std::vector<double*> jac_ptrs;
  for (size_t k = 0; k < sizes.size(); ++k) {
    J[k] = RowMajorMat::Constant(9, sizes[k], std::nan(""));
    jac_ptrs.push_back(J[k].data());
  }
  Evaluation e;
  const std::vector<const double*> params = p.params();
  EXPECT_TRUE(cost.Evaluate(params.data(), e.r.data(), jac_ptrs.data()));
  const PoseManifold manifold;
  for (size_t k = 0; k < sizes.size(); ++k) {
    e.J_amb.push_back(J[k]);
    if (sizes[k] == pose::kAmbient) {
      Eigen::Matrix<double, 7, 6, Eigen::RowMajor> P;
      manifold.PlusJacobian(params[k], P.data());
      e.J_tan.push_back(J[k] * P);
    } else {
      e.J_tan.push_back(J[k]);
    }
  }
  return e;
}

TEST(ImuFactorTest, AnalyticResidualMatchesAutoDiff) {
  double worst_abs = 0.0, worst_rel = 0.0;
  for (const ProbePoint& p : ProbePoints()) {
    const std::unique_ptr<ceres::CostFunction> analytic(ImuFactor::Create(p.preint, GravityWorld(kG)));
    const std::unique_ptr<ceres::CostFunction> autodiff(ImuFactor::CreateAutoDiff(p.preint, GravityWorld(kG)));
    const std::vector<const double*> params = p.params();
    Vec9 r_analytic, r_autodiff;
    ASSERT_TRUE(analytic->Evaluate(params.data(), r_analytic.data(), nullptr));
    ASSERT_TRUE(autodiff->Evaluate(params.data(), r_autodiff.data(), nullptr));
    // With Jacobians requested the residual is the same.
    const Evaluation e = EvaluateWithJacobians(*analytic, p);
    EXPECT_EQ(e.r, r_analytic) << p.name;
    const double diff = (r_analytic - r_autodiff).cwiseAbs().maxCoeff();
    const double rel = diff / std::max(1.0, r_autodiff.cwiseAbs().maxCoeff());
    EXPECT_LE(rel, 1e-12) << p.name << "\nanalytic " << r_analytic.transpose() << "\nautodiff "
                          << r_autodiff.transpose();
    worst_abs = std::max(worst_abs, diff);
    worst_rel = std::max(worst_rel, rel);
  }
  std::printf("[ imu res  ] analytic vs autodiff residual: max |Δr| = %.2g (relative to max(1, |r|∞): %.2g)\n",
              worst_abs, worst_rel);
}

TEST(ImuFactorTest, AnalyticJacobiansMatchAutoDiff) {
  const char* kBlockNames[] = {"pose_i", "vel_i", "bias_i", "pose_j", "vel_j"};
  double worst = 0.0, worst_row = 0.0;
  int num_points = 0;
  for (const ProbePoint& p : ProbePoints()) {
    const std::unique_ptr<ceres::CostFunction> analytic(ImuFactor::Create(p.preint, GravityWorld(kG)));
    const std::unique_ptr<ceres::CostFunction> autodiff(ImuFactor::CreateAutoDiff(p.preint, GravityWorld(kG)));
    const Evaluation a = EvaluateWithJacobians(*analytic, p);
    const Evaluation b = EvaluateWithJacobians(*autodiff, p);
    for (size_t k = 0; k < a.J_tan.size(); ++k) {
      ASSERT_TRUE(a.J_amb[k].allFinite()) << p.name << " " << kBlockNames[k];
      // Tangent Jacobians (what Ceres uses) agree, relative to the block's largest entry.
      const double scale = std::max(b.J_tan[k].cwiseAbs().maxCoeff(), 1e-300);
      const double err = (a.J_tan[k] - b.J_tan[k]).cwiseAbs().maxCoeff() / scale;
      EXPECT_LE(err, 1e-9) << p.name << ", block " << kBlockNames[k] << "\nanalytic\n"
                           << a.J_tan[k] << "\nautodiff\n"
                           << b.J_tan[k];
      worst = std::max(worst, err);
      // Stricter: relative to the largest entry of each row of the block.
      for (int i = 0; i < 9; ++i) {
        const double row_scale = std::max(b.J_tan[k].row(i).cwiseAbs().maxCoeff(), 1e-300);
        worst_row = std::max(worst_row, (a.J_tan[k] - b.J_tan[k]).row(i).cwiseAbs().maxCoeff() / row_scale);
      }
    }
    // The pose blocks' ambient Jacobians are the tangent ones lifted by PoseManifold's MinusJacobian.
    const PoseManifold manifold;
    const std::vector<const double*> params = p.params();
    for (size_t k : {size_t{0}, size_t{3}}) {
      Eigen::Matrix<double, 6, 7, Eigen::RowMajor> M;
      manifold.MinusJacobian(params[k], M.data());
      const double scale = a.J_amb[k].cwiseAbs().maxCoeff();
      EXPECT_LE((a.J_amb[k] - a.J_tan[k] * M).cwiseAbs().maxCoeff(), 1e-12 * scale) << p.name;
    }
    ++num_points;
  }
  std::printf("[ imu jac  ] analytic vs autodiff tangent Jacobians over %d points: worst %.2g (relative to the "
              "block's largest entry; %.2g relative to each row's)\n",
              num_points, worst, worst_row);
}

TEST(ImuFactorTest, AnalyticJacobiansOfSomeBlocksOnly) {
  // Ceres passes nullptr for the Jacobians of constant blocks: the others must not change.
  const ProbePoint p = ProbePoints()[2];
  const std::unique_ptr<ceres::CostFunction> cost(ImuFactor::Create(p.preint, GravityWorld(kG)));
  const Evaluation full = EvaluateWithJacobians(*cost, p);
  for (int k = 0; k < 5; ++k) {
    Eigen::Matrix<double, 9, 7, Eigen::RowMajor> J;
    std::vector<double*> jac_ptrs(5, nullptr);
    jac_ptrs[k] = J.data();
    Vec9 r;
    const std::vector<const double*> params = p.params();
    ASSERT_TRUE(cost->Evaluate(params.data(), r.data(), jac_ptrs.data()));
    EXPECT_EQ(r, full.r);
    const int n = cost->parameter_block_sizes()[k];
    const Eigen::Map<const Eigen::Matrix<double, 9, Eigen::Dynamic, Eigen::RowMajor>> J_k(J.data(), 9, n);
    EXPECT_EQ(MatX(J_k), full.J_amb[k]) << "block " << k;
  }
}

TEST(ImuFactorTest, JacobiansMatchNumeric) {
  Vec6 offset;
  offset << 1e-3, -2e-3, 1e-3, 1e-2, -1e-2, 2e-2;
  const ImuScenario s = MakeScenario(100, 0.01, offset);
  // The production cost function (analytic Jacobians).
  std::unique_ptr<ceres::CostFunction> cost(ImuFactor::Create(s.preint, GravityWorld(kG)));
  ASSERT_EQ(cost->num_residuals(), 9);
  ASSERT_EQ(cost->parameter_block_sizes(), (std::vector<int32_t>{7, 3, 6, 7, 3}));
  const PoseManifold manifold;
  const auto manifolds = ImuManifolds(&manifold);

  double worst = 0.0;
  // Near truth.
  worst = std::max(worst, test::CheckJacobians(*cost, manifolds,
                                               {s.pose_i.data(), s.vel_i.data(), s.bias.data(),
                                                s.pose_j.data(), s.vel_j.data()},
                                               1e-6, "near truth"));
  // Random points: large rotation and velocity errors, biases away from the linearisation point. Rotation
  // errors stay well below π, where Log (shortest rotation) jumps and finite differences mean nothing.
  const ImuFactor factor(s.preint, GravityWorld(kG));
  double max_r_theta = 0.0;
  std::mt19937 rng(3);
  for (int trial = 0; trial < 10; ++trial) {
    Vec6 d_i, d_j;
    d_i << test::RandomVec3(rng, 1.0), test::RandomVec3(rng, 0.3);
    d_j << test::RandomVec3(rng, 1.0), test::RandomVec3(rng, 0.3);
    const test::PoseBlock pose_i = test::PosePlus(s.pose_i, d_i), pose_j = test::PosePlus(s.pose_j, d_j);
    const Vec3 vel_i = s.vel_i + test::RandomVec3(rng, 1.0), vel_j = s.vel_j + test::RandomVec3(rng, 1.0);
    Vec6 bias = s.bias;
    bias.head<3>() += test::RandomVec3(rng, 0.02);
    bias.tail<3>() += test::RandomVec3(rng, 0.2);
    {
      Vec9 r;
      factor(pose_i.data(), vel_i.data(), bias.data(), pose_j.data(), vel_j.data(), r.data());
      max_r_theta = std::max(max_r_theta, (factor.sqrt_information().inverse() * r).tail<3>().norm());
    }
    worst = std::max(
        worst, test::CheckJacobians(*cost, manifolds,
                                    {pose_i.data(), vel_i.data(), bias.data(), pose_j.data(), vel_j.data()},
                                    1e-6, "random point " + std::to_string(trial)));
  }
  std::printf("[ imu jac  ] worst relative error over 11 probes: %.2g (largest |r_θ| %.2f rad)\n", worst,
              max_r_theta);
}

TEST(ImuFactorTest, SqrtInformationOfSingleSampleIsFinite) {
  // One sample: δp and δv are driven by the same accelerometer noise, so Σ is singular.
  Preintegration pre(Vec3::Zero(), Vec3::Zero(), 2e-3, 2e-2);
  pre.Integrate(Vec3(0.1, 0.0, 0.0), Vec3(0.0, 0.0, kG), 0.01);
  const Mat9 S = SqrtInformation(pre.cov());
  EXPECT_TRUE(S.allFinite());
  // Where Σ has support, SᵀS still inverts it.
  const Eigen::SelfAdjointEigenSolver<Mat9> es(pre.cov());
  const Vec9 v = es.eigenvectors().col(8);
  EXPECT_NEAR(v.transpose() * S.transpose() * S * pre.cov() * v, 1.0, 1e-6);
}

}  // namespace
}  // namespace gins
