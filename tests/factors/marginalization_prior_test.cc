#include "factors/marginalization_prior.h"

#include <ceres/crs_matrix.h>
#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <memory>
#include <random>
#include <vector>

#include "core/imu_kernel.h"
#include "core/preintegration.h"
#include "factor_test_util.h"
#include "factors/bias_rw_factor.h"
#include "factors/gnss_factor.h"
#include "factors/heading_factor.h"
#include "factors/imu_factor.h"
#include "factors/nhc_factor.h"
#include "factors/wheel_factor.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kG = 9.81;
constexpr int kNumKf = 3;

// A convex loss (ρ'' > 0), to exercise the curvature branch of the Corrector; Ceres's own losses are concave.
class ConvexLoss final : public ceres::LossFunction {
 public:
  void Evaluate(double s, double rho[3]) const override {
    rho[0] = s + 0.05 * s * s;
    rho[1] = 1.0 + 0.1 * s;
    rho[2] = 0.1;
  }
};

MatX Dense(const ceres::CRSMatrix& crs) {
  MatX M = MatX::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) M(r, crs.cols[k]) = crs.values[k];
  }
  return M;
}

// Three keyframes 0.5 s apart joined by IMU factors, with GNSS (one robust), heading, wheel (scale held
// constant), NHC and bias random-walk factors. States are perturbed away from the truth so that residuals
// and gradients are not zero.
class SmallWindow {
 public:
  SmallWindow() {
    std::mt19937 rng(21);
    const Vec3 g_w = GravityWorld(kG);
    Vec6 bias_true;
    bias_true << 0.01, -0.02, 0.005, 0.1, 0.05, -0.08;
    Kinematics x;
    x.p = Vec3(10.0, -4.0, 2.0);
    x.v = Vec3(6.0, 1.0, 0.0);
    x.q = ExpQuat<double>(Vec3(0.02, -0.03, 0.3));
    std::vector<Kinematics> truth{x};
    for (int i = 0; i + 1 < kNumKf; ++i) {
      auto pre = std::make_shared<Preintegration>(bias_true.head<3>(), bias_true.tail<3>(), 2e-3, 2e-2);
      for (int k = 0; k < 50; ++k) {
        const double t = 0.5 * i + 0.01 * k;
        const Vec3 omega(0.05 * std::sin(2.0 * t), -0.03, 0.2 * std::cos(t));
        const Vec3 acc(0.5 * std::cos(1.3 * t), 0.4 * std::sin(2.1 * t), kG + 0.1 * std::sin(t));
        pre->Integrate(omega + bias_true.head<3>(), acc + bias_true.tail<3>(), 0.01);
        x = ImuStep(x, omega, acc, g_w, 0.01);
      }
      truth.push_back(x);
      imu_costs_.emplace_back(ImuFactor::Create(pre, g_w));
    }
    const Vec3 lever_b(-0.17, -0.2, 0.1);
    for (int i = 0; i < kNumKf; ++i) {
      Vec6 d;
      d << test::RandomVec3(rng, 0.1), test::RandomVec3(rng, 0.01);
      pose_[i] = test::PosePlus(test::MakePose(truth[i].p, truth[i].q), d);
      vel_[i] = truth[i].v + test::RandomVec3(rng, 0.05);
      bias_[i] = bias_true;
      bias_[i].head<3>() += test::RandomVec3(rng, 1e-3);
      bias_[i].tail<3>() += test::RandomVec3(rng, 1e-2);
      const Vec3 z_w = truth[i].p + truth[i].q * lever_b + test::RandomVec3(rng, 0.05);
      gnss_costs_.emplace_back(GnssFactor::Create(z_w, Vec3(0.05, 0.05, 0.1), lever_b));
      const Mat3 R_wG = truth[i].q.toRotationMatrix() * QuatFromYaw(0.2).toRotationMatrix();
      heading_costs_.emplace_back(HeadingFactor::Create(YawOfXAxis<double>(R_wG) + 0.01, 0.01, 0.2));
      const double speed = (truth[i].q.conjugate() * truth[i].v).x();
      wheel_costs_.emplace_back(WheelFactor::Create(scale_ * speed + 0.05, 0.1));
      nhc_costs_.emplace_back(NhcFactor::Create(0.1));
    }
    for (int i = 0; i + 1 < kNumKf; ++i) bias_costs_.emplace_back(BiasRwFactor::Create(1e-3, 1e-2, 0.5));
  }

  struct Residual {
    ceres::CostFunction* cost;
    ceres::LossFunction* loss;
    std::vector<double*> blocks;
    bool touches_kf0;
  };

  // All residual blocks of the window.
  std::vector<Residual> Residuals() {
    std::vector<Residual> out;
    for (int i = 0; i + 1 < kNumKf; ++i) {
      out.push_back(
          {imu_costs_[i].get(),
           nullptr,
           {pose_[i].data(), vel_[i].data(), bias_[i].data(), pose_[i + 1].data(), vel_[i + 1].data()},
           i == 0});
      out.push_back({bias_costs_[i].get(), nullptr, {bias_[i].data(), bias_[i + 1].data()}, i == 0});
    }
    for (int i = 0; i < kNumKf; ++i) {
      out.push_back({gnss_costs_[i].get(), i == 0 ? &cauchy_ : nullptr, {pose_[i].data()}, i == 0});
      out.push_back({heading_costs_[i].get(), nullptr, {pose_[i].data()}, i == 0});
      out.push_back({wheel_costs_[i].get(),
                     i == 0 ? &convex_ : nullptr,
                     {pose_[i].data(), vel_[i].data(), &scale_},
                     i == 0});
      out.push_back({nhc_costs_[i].get(), nullptr, {pose_[i].data(), vel_[i].data()}, i == 0});
    }
    return out;
  }

  std::vector<double*> KfBlocks(int i) { return {pose_[i].data(), vel_[i].data(), bias_[i].data()}; }

  // A problem over the given residuals that owns nothing; scale held constant.
  std::unique_ptr<ceres::Problem> MakeProblem(const std::vector<Residual>& residuals) {
    ceres::Problem::Options options;
    options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    auto problem = std::make_unique<ceres::Problem>(options);
    for (int i = 0; i < kNumKf; ++i) problem->AddParameterBlock(pose_[i].data(), 7, &pose_manifold_);
    for (const Residual& r : residuals) problem->AddResidualBlock(r.cost, r.loss, r.blocks);
    if (problem->HasParameterBlock(&scale_)) problem->SetParameterBlockConstant(&scale_);
    return problem;
  }

  PoseManifold pose_manifold_;
  test::PoseBlock pose_[kNumKf];
  Vec3 vel_[kNumKf];
  Vec6 bias_[kNumKf];
  double scale_ = 0.98;

 private:
  std::vector<std::unique_ptr<ceres::CostFunction>> imu_costs_, gnss_costs_, heading_costs_, wheel_costs_,
      nhc_costs_, bias_costs_;
  ceres::CauchyLoss cauchy_{1.0};
  ConvexLoss convex_;
};

// H = JᵀJ and b = Jᵀr of a problem in tangent space, columns in the order of `blocks`.
void Information(ceres::Problem* problem, const std::vector<double*>& blocks, MatX* H, VecX* b) {
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = blocks;
  std::vector<double> gradient;
  ceres::CRSMatrix jacobian;
  ASSERT_TRUE(problem->Evaluate(options, nullptr, nullptr, &gradient, &jacobian));
  const MatX J = Dense(jacobian);
  *H = J.transpose() * J;
  *b = Eigen::Map<const VecX>(gradient.data(), static_cast<int>(gradient.size()));
}

std::vector<double*> Concat(std::vector<double*> a, const std::vector<double*>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

TEST(MarginalizationPriorTest, PriorEqualsSchurComplementOfFullProblem) {
  SmallWindow w;
  const std::vector<SmallWindow::Residual> all = w.Residuals();

  // Full problem information over all keyframes, Schur-complemented by hand (dense Eigen).
  const std::vector<double*> order = Concat(Concat(w.KfBlocks(0), w.KfBlocks(1)), w.KfBlocks(2));
  MatX H;
  VecX b;
  Information(w.MakeProblem(all).get(), order, &H, &b);
  const int m = 15, k = static_cast<int>(H.rows()) - m;
  ASSERT_EQ(k, 30);
  const MatX H_mm_inv = H.topLeftCorner(m, m).inverse();
  const MatX H_schur =
      H.bottomRightCorner(k, k) - H.bottomLeftCorner(k, m) * H_mm_inv * H.topRightCorner(m, k);
  const VecX b_schur = b.tail(k) - H.bottomLeftCorner(k, m) * H_mm_inv * b.head(m);

  // Marginalise keyframe 0 with the residuals that touch it.
  MarginalizationInfo info;
  for (int i = 0; i < 2; ++i) {
    const auto role = i == 0 ? MarginalizationInfo::Role::kMarginalize : MarginalizationInfo::Role::kKeep;
    info.AddParameterBlock(w.pose_[i].data(), BlockKind::kPose, 7, role);
    info.AddParameterBlock(w.vel_[i].data(), BlockKind::kEuclidean, 3, role);
    info.AddParameterBlock(w.bias_[i].data(), BlockKind::kEuclidean, 6, role);
  }
  info.AddParameterBlock(&w.scale_, BlockKind::kEuclidean, 1, MarginalizationInfo::Role::kConstant);
  std::vector<SmallWindow::Residual> rest;
  for (const auto& r : all) {
    if (r.touches_kf0) {
      info.AddResidualBlock(r.cost, r.loss, r.blocks);
    } else {
      rest.push_back(r);
    }
  }
  ASSERT_TRUE(info.Marginalize());
  ASSERT_EQ(info.kept_parameter_blocks(), w.KfBlocks(1));
  std::unique_ptr<MarginalizationPrior> prior = info.CreatePrior();
  ASSERT_NE(prior, nullptr);

  const Eigen::SelfAdjointEigenSolver<MatX> es(info.marginal_information());
  std::printf("[ marg     ] prior rows %d of 15; eigenvalues of H* in [%.3g, %.3g]\n", prior->num_residuals(),
              es.eigenvalues().minCoeff(), es.eigenvalues().maxCoeff());

  // Prior alone: JᵀJ = H*, Jᵀr0 = b* of the marginalised factors.
  const MatX& J = prior->J();
  EXPECT_LT((J.transpose() * J - info.marginal_information()).norm() / info.marginal_information().norm(),
            1e-12);
  EXPECT_LT((J.transpose() * prior->r0() - info.marginal_gradient()).norm() / info.marginal_gradient().norm(),
            1e-12);

  // Prior + the remaining factors, evaluated by Ceres through the manifolds, = Schur complement of the full
  // problem.
  std::unique_ptr<ceres::Problem> reduced = w.MakeProblem(rest);
  reduced->AddResidualBlock(prior.get(), nullptr, info.kept_parameter_blocks());
  MatX H_red;
  VecX b_red;
  Information(reduced.get(), Concat(w.KfBlocks(1), w.KfBlocks(2)), &H_red, &b_red);
  const double err_H = (H_red - H_schur).norm() / H_schur.norm();
  const double err_b = (b_red - b_schur).norm() / b_schur.norm();
  std::printf("[ marg     ] |H_red - H_schur|/|H_schur| = %.2g, |b_red - b_schur|/|b_schur| = %.2g\n", err_H,
              err_b);
  EXPECT_LT(err_H, 1e-9);
  EXPECT_LT(err_b, 1e-9);
  // Release before the problem (which does not own it) goes.
  reduced.reset();
}

TEST(MarginalizationPriorTest, EvaluatesCorrectlyAwayFromLinearizationPoint) {
  // A prior on (pose, vel) with a random full-rank J.
  std::mt19937 rng(22);
  const test::PoseBlock pose0 = test::RandomPose(rng);
  const Vec3 vel0(1.0, 2.0, 3.0);
  std::vector<PriorBlock> blocks{
      PriorBlock{BlockKind::kPose, 7, 6, std::vector<double>(pose0.begin(), pose0.end())},
      PriorBlock{BlockKind::kEuclidean, 3, 3, std::vector<double>(vel0.data(), vel0.data() + 3)}};
  std::normal_distribution<double> n(0.0, 1.0);
  MatX J(9, 9);
  for (int i = 0; i < J.size(); ++i) J.data()[i] = n(rng);
  VecX r0(9);
  for (int i = 0; i < 9; ++i) r0[i] = n(rng);
  const MarginalizationPrior prior(blocks, J, r0);
  const PoseManifold manifold;

  // At x0: residual r0, tangent Jacobian exactly J.
  {
    const double* params[2] = {pose0.data(), vel0.data()};
    VecX r(9);
    Eigen::Matrix<double, 9, 7, Eigen::RowMajor> J_pose;
    Eigen::Matrix<double, 9, 3, Eigen::RowMajor> J_vel;
    double* jacs[2] = {J_pose.data(), J_vel.data()};
    ASSERT_TRUE(prior.Evaluate(params, r.data(), jacs));
    EXPECT_LT((r - r0).norm(), 1e-14);
    Eigen::Matrix<double, 7, 6, Eigen::RowMajor> P;
    manifold.PlusJacobian(pose0.data(), P.data());
    EXPECT_LT((J_pose * P - J.leftCols(6)).norm(), 1e-12);
    EXPECT_LT((J_vel - J.rightCols(3)).norm(), 1e-14);
  }
  // Away from x0 (rotations up to ~1 rad): GradientChecker, and r = r0 + J·(x ⊟ x0).
  double worst = 0.0;
  for (int trial = 0; trial < 10; ++trial) {
    Vec6 d;
    d << test::RandomVec3(rng, 1.0), test::RandomVec3(rng, 0.6);
    const test::PoseBlock pose = test::PosePlus(pose0, d);
    const Vec3 vel = vel0 + test::RandomVec3(rng, 1.0);
    worst = std::max(worst, test::CheckJacobians(prior, {&manifold, nullptr}, {pose.data(), vel.data()}, 1e-6,
                                                 "prior trial " + std::to_string(trial)));
    const double* params[2] = {pose.data(), vel.data()};
    VecX r(9);
    prior.Evaluate(params, r.data(), nullptr);
    VecX dx(9);
    dx << d, vel - vel0;
    EXPECT_LT((r - (r0 + J * dx)).norm(), 1e-9);
  }
  std::printf("[ prior jac] worst relative error away from x0: %.2g\n", worst);
}

TEST(MarginalizationPriorTest, UnconstrainedDirectionsAreDropped) {
  // One scalar factor on a 3-vector: the prior has rank 1.
  double x_marg[1] = {0.5};
  double x_keep[3] = {1.0, 2.0, 3.0};
  std::unique_ptr<ceres::CostFunction> cost(BiasRwFactor::Create(1.0, 1.0, 1.0));  // any 6-vs-6 factor
  double b_i[6] = {0, 0, 0, 0, 0, 0}, b_j[6] = {1, 0, 0, 0, 0, 0};
  MarginalizationInfo info;
  info.AddParameterBlock(b_i, BlockKind::kEuclidean, 6, MarginalizationInfo::Role::kMarginalize);
  info.AddParameterBlock(b_j, BlockKind::kEuclidean, 6, MarginalizationInfo::Role::kKeep);
  info.AddParameterBlock(x_marg, BlockKind::kEuclidean, 1, MarginalizationInfo::Role::kMarginalize);
  info.AddParameterBlock(x_keep, BlockKind::kEuclidean, 3, MarginalizationInfo::Role::kKeep);
  info.AddResidualBlock(cost.get(), nullptr, {b_i, b_j});
  ASSERT_TRUE(info.Marginalize());
  // b_i − b_j alone: marginalising b_i removes all information on b_j; untouched blocks are not kept.
  EXPECT_EQ(info.kept_parameter_blocks(), std::vector<double*>{b_j});
  EXPECT_LT(info.marginal_information().norm(), 1e-9);
  EXPECT_EQ(info.CreatePrior(), nullptr);
}

}  // namespace
}  // namespace gins
