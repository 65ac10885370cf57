// FejCost: the residual at the current values, the Jacobians at the active first estimates, and for a pose
// block a Jacobian that Ceres's product with PlusJacobian at the current value turns into the tangent
// Jacobian at the first estimate.
#include "factors/fej_cost.h"

#include <ceres/crs_matrix.h>
#include <ceres/problem.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "factor_test_util.h"
#include "factors/gnss_factor.h"
#include "factors/wheel_factor.h"

namespace gins {
namespace GINS_TEST_FILE {

using RowMatX = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Mat76 = Eigen::Matrix<double, pose::kAmbient, pose::kTangent, Eigen::RowMajor>;

struct Evaluation {
  bool ok = false;
  VecX r;
  std::vector<RowMatX> J;  // ambient, per block
};

Evaluation EvaluateCost(const ceres::CostFunction& cost, const std::vector<const double*>& params,
                        bool with_jacobians = true) {
  Evaluation e;
  e.r = VecX::Zero(cost.num_residuals());
  std::vector<double*> jacobians;
  for (int size : cost.parameter_block_sizes()) {
    e.J.push_back(RowMatX::Zero(cost.num_residuals(), size));
    jacobians.push_back(e.J.back().data());
  }
  e.ok = cost.Evaluate(params.data(), e.r.data(), with_jacobians ? jacobians.data() : nullptr);
  return e;
}

Mat76 PlusJacobian(const double* x) {
  Mat76 P;
  PoseManifold().PlusJacobian(x, P.data());
  return P;
}

// A wheel factor's blocks at two different points: the current values and the first estimates.
class FejCostTest : public ::testing::Test {
 protected:
  FejCostTest() {
    std::mt19937 rng(7);
    pose_ = test::RandomPose(rng);
    Vec6 d;
    d << 0.4, -0.3, 0.2, 0.25, -0.35, 0.3;  // far enough that the Jacobians differ clearly
    pose_fej_ = test::PosePlus(pose_, d);
    vel_ = test::RandomVec3(rng, 5.0);
    vel_fej_ = vel_ + Vec3(0.7, -0.4, 0.3);
  }
  static ceres::CostFunction* Wheel() { return WheelFactor::Create(4.2, 0.1); }
  static ceres::CostFunction* Gnss() {
    return GnssFactor::Create(Vec3(3.0, -1.0, 2.0), Vec3(0.5, 0.4, 0.8), Vec3(-0.6, 0.8, 0.3));
  }

  test::PoseBlock pose_, pose_fej_;
  Vec3 vel_, vel_fej_;
  double scale_ = 1.03, scale_fej_ = 0.97;
  bool active_ = false;
};

TEST_F(FejCostTest, WithoutAnActiveFirstEstimateItIsTheInnerCostExactly) {
  // One block with an inactive first estimate, one without a first estimate, one without a flag.
  FejCost fej(Wheel(), {{pose_fej_.data(), &active_, true}, {nullptr, &active_, false}, {&scale_fej_, nullptr, false}});
  const std::unique_ptr<ceres::CostFunction> inner(Wheel());
  const std::vector<const double*> now = {pose_.data(), vel_.data(), &scale_};
  const Evaluation a = EvaluateCost(fej, now), b = EvaluateCost(*inner, now);
  ASSERT_TRUE(a.ok && b.ok);
  for (int i = 0; i < a.r.size(); ++i) EXPECT_EQ(a.r[i], b.r[i]);
  for (size_t k = 0; k < a.J.size(); ++k) {
    for (int i = 0; i < a.J[k].size(); ++i) EXPECT_EQ(a.J[k].data()[i], b.J[k].data()[i]) << "block " << k;
  }
  // The flag is read at each evaluation: raised, the pose Jacobian changes; lowered, it is exact again.
  active_ = true;
  EXPECT_GT((EvaluateCost(fej, now).J[0] - b.J[0]).cwiseAbs().maxCoeff(), 1e-3);
  active_ = false;
  EXPECT_EQ(EvaluateCost(fej, now).J[0], b.J[0]);
}

TEST_F(FejCostTest, ResidualAtTheCurrentValuesJacobiansAtTheFirstEstimates) {
  // Euclidean blocks: velocity and scale linearised at their first estimates, the pose at its value.
  active_ = true;
  FejCost fej(Wheel(),
              {{pose_fej_.data(), nullptr, true}, {vel_fej_.data(), &active_, false}, {&scale_fej_, &active_, false}});
  const std::unique_ptr<ceres::CostFunction> inner(Wheel());
  const Evaluation a = EvaluateCost(fej, {pose_.data(), vel_.data(), &scale_});
  const Evaluation at_now = EvaluateCost(*inner, {pose_.data(), vel_.data(), &scale_});
  const Evaluation at_fej = EvaluateCost(*inner, {pose_.data(), vel_fej_.data(), &scale_fej_});
  ASSERT_TRUE(a.ok && at_now.ok && at_fej.ok);
  EXPECT_EQ(a.r, at_now.r);
  EXPECT_NE(a.r, at_fej.r);
  for (size_t k = 0; k < a.J.size(); ++k) EXPECT_EQ(a.J[k], at_fej.J[k]) << "block " << k;
  EXPECT_GT((at_now.J[0] - at_fej.J[0]).cwiseAbs().maxCoeff(), 1e-3);  // the test can tell them apart

  // Without Jacobians requested, only the residual at the current values.
  const Evaluation r_only = EvaluateCost(fej, {pose_.data(), vel_.data(), &scale_}, /*with_jacobians=*/false);
  ASSERT_TRUE(r_only.ok);
  EXPECT_EQ(r_only.r, at_now.r);
}

// J_returned · Plus'(x_current) == J_inner(x_fej) · Plus'(x_fej): what Ceres computes is the tangent
// Jacobian at the first estimate.
void ExpectTangentJacobianAtFirstEstimate(const RowMatX& J_returned, const RowMatX& J_inner_fej, const double* x_now,
                                          const double* x_fej) {
  const RowMatX tangent_returned = J_returned * PlusJacobian(x_now);
  const RowMatX tangent_fej = J_inner_fej * PlusJacobian(x_fej);
  const double scale = tangent_fej.cwiseAbs().maxCoeff();
  EXPECT_LT((tangent_returned - tangent_fej).cwiseAbs().maxCoeff(), 1e-12 * scale)
      << "returned (tangent):\n"
      << tangent_returned << "\nat the first estimate:\n"
      << tangent_fej;
}

TEST_F(FejCostTest, PoseBlockGivesTheTangentJacobianAtTheFirstEstimate) {
  active_ = true;
  {
    FejCost fej(Gnss(), {{pose_fej_.data(), &active_, true}});
    const std::unique_ptr<ceres::CostFunction> inner(Gnss());
    const Evaluation a = EvaluateCost(fej, {pose_.data()});
    const Evaluation at_now = EvaluateCost(*inner, {pose_.data()});
    const Evaluation at_fej = EvaluateCost(*inner, {pose_fej_.data()});
    ASSERT_TRUE(a.ok && at_now.ok && at_fej.ok);
    EXPECT_EQ(a.r, at_now.r);
    ExpectTangentJacobianAtFirstEstimate(a.J[0], at_fej.J[0], pose_.data(), pose_fej_.data());
    // The inner Jacobian at the first estimate, unconverted, would not do: Plus' differs between the points.
    const RowMatX unconverted = at_fej.J[0] * PlusJacobian(pose_.data());
    EXPECT_GT((unconverted - at_fej.J[0] * PlusJacobian(pose_fej_.data())).cwiseAbs().maxCoeff(), 1e-3);
  }
  {
    // With other blocks at their current values: their Jacobians are the inner ones at the mixed point.
    FejCost fej(Wheel(),
                {{pose_fej_.data(), &active_, true}, {vel_fej_.data(), nullptr, false}, {nullptr, nullptr, false}});
    const std::unique_ptr<ceres::CostFunction> inner(Wheel());
    const Evaluation a = EvaluateCost(fej, {pose_.data(), vel_.data(), &scale_});
    const Evaluation mixed = EvaluateCost(*inner, {pose_fej_.data(), vel_.data(), &scale_});
    ASSERT_TRUE(a.ok && mixed.ok);
    ExpectTangentJacobianAtFirstEstimate(a.J[0], mixed.J[0], pose_.data(), pose_fej_.data());
    EXPECT_EQ(a.J[1], mixed.J[1]);
    EXPECT_EQ(a.J[2], mixed.J[2]);
  }
}

TEST_F(FejCostTest, CeresSeesTheTangentJacobianAtTheFirstEstimate) {
  // Through a Problem: Ceres multiplies by PlusJacobian at the current value itself.
  active_ = true;
  PoseManifold manifold;
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  problem.AddParameterBlock(pose_.data(), pose::kAmbient, &manifold);
  problem.AddResidualBlock(new FejCost(Gnss(), {{pose_fej_.data(), &active_, true}}), nullptr, pose_.data());
  ceres::CRSMatrix crs;
  ASSERT_TRUE(problem.Evaluate(ceres::Problem::EvaluateOptions(), nullptr, nullptr, nullptr, &crs));
  ASSERT_EQ(crs.num_cols, pose::kTangent);
  RowMatX J = RowMatX::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) J(r, crs.cols[k]) = crs.values[k];
  }
  const std::unique_ptr<ceres::CostFunction> inner(Gnss());
  const RowMatX expected = EvaluateCost(*inner, {pose_fej_.data()}).J[0] * PlusJacobian(pose_fej_.data());
  EXPECT_LT((J - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace gins
