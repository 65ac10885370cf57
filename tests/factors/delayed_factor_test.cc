// The delayed GNSS factors (factors/delayed_factor.h): DelayedAttachedCostFunction's analytic Jacobians equal
// autodiff of the same residual and numeric differences through the pose manifold, for every measurement,
// flat and rotating Earth, td included; DelayedAtKeyframeCostFunction's likewise (against the autodiff of
// DelayedAtKeyframeFactor and numeric differences); at
// td = 0 both are the undelayed factors; and the shift means what it says: a fix taken td before its stamp
// on a body at constant velocity has a zero residual at that td and not at 0.
#include "factors/delayed_factor.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <string>

#include "factor_test_util.h"
#include "factors/gnss_factor.h"

namespace gins {
namespace GINS_TEST_FILE {

template <class M>
void ExpectDelayedMatches(const M& measurement, const std::string& what) {
  const Delayed<M> delayed{measurement, Vec3(1.5, -0.8, 0.3), Vec3(0.2, -0.1, 0.6)};
  for (const Vec3& rate : {Vec3(Vec3::Zero()), Vec3(0.01, 0.03, 0.04)}) {
    const test::AttachedInterval s = test::MakeAttachedInterval(rate);
    const std::unique_ptr<ceres::CostFunction> analytic(
        DelayedAttachedCostFunction<M>::Create(s.preint, s.earth, delayed));
    const std::unique_ptr<ceres::CostFunction> autodiff(
        DelayedAttachedCostFunction<M>::CreateAutoDiff(s.preint, s.earth, delayed));
    const std::unique_ptr<ceres::CostFunction> at_keyframe(DelayedAtKeyframeFactor<M>::Create(delayed));
    const std::unique_ptr<ceres::CostFunction> at_keyframe_autodiff(
        DelayedAtKeyframeFactor<M>::CreateAutoDiff(delayed));
    constexpr int R = M::kResidualDim;
    const PoseManifold manifold;
    std::mt19937 rng(23);
    for (int trial = 0; trial < 6; ++trial) {
      const auto [pose, v, b] = test::PerturbedBlocks(rng, s.pose_i, s.vel_i, s.bias);
      const double td = 0.25 * (trial - 2);  // −0.5 … 0.75 s
      const std::string at = what + " rate " + std::to_string(rate.norm()) + " td " + std::to_string(td);
      test::ExpectSameResidualAndJacobians(*analytic, *autodiff, {&manifold, nullptr, nullptr, nullptr},
                                           {pose.data(), v.data(), b.data(), &td}, at + " autodiff");
      Eigen::Matrix<double, R, 1> r, J_td;
      Eigen::Matrix<double, R, 7, Eigen::RowMajor> J_pose;
      Eigen::Matrix<double, R, 3, Eigen::RowMajor> J_vel;
      Eigen::Matrix<double, R, 6, Eigen::RowMajor> J_bias;
      const double* params[] = {pose.data(), v.data(), b.data(), &td};
      double* jacobians[] = {J_pose.data(), J_vel.data(), J_bias.data(), J_td.data()};
      ASSERT_TRUE(analytic->Evaluate(params, r.data(), jacobians));
      EXPECT_GT(J_td.norm(), 0.0) << at << ": the offset must be observable";
      test::CheckJacobians(*analytic, {&manifold, nullptr, nullptr, nullptr}, {pose.data(), v.data(), b.data(), &td},
                           1e-6, at + " numeric");
      test::CheckJacobians(*at_keyframe, {&manifold, nullptr, nullptr}, {pose.data(), v.data(), &td}, 1e-6,
                           at + " at keyframe, numeric");
      test::ExpectSameResidualAndJacobians(*at_keyframe, *at_keyframe_autodiff, {&manifold, nullptr, nullptr},
                                           {pose.data(), v.data(), &td}, at + " at keyframe, autodiff");
    }
  }
}

TEST(DelayedFactorTest, GnssPositionJacobiansMatchAutodiffAndNumeric) {
  ExpectDelayedMatches(GnssAtTime{Vec3(20.0, -1.0, 0.5), Vec3(2.0, 1.5, 1.0), Vec3(0.3, -0.2, 1.1)}, "gnss");
}

TEST(DelayedFactorTest, HeadingJacobiansMatchAutodiffAndNumeric) {
  ExpectDelayedMatches(HeadingAtTime{1.7, 1.0 / 0.02, 0.3}, "heading");
}

TEST(DelayedFactorTest, GnssVelocityJacobiansMatchAutodiffAndNumeric) {
  ExpectDelayedMatches(
      GnssVelocityAtTime{Vec3(9.0, -3.0, 2.5), Vec3(10.0, 10.0, 5.0), Vec3(0.1, -0.2, 0.4), Vec3(0.3, -0.2, 1.1)}, "gvel");
}

TEST(DelayedFactorTest, AtZeroOffsetTheUndelayedFactors) {
  const test::AttachedInterval s = test::MakeAttachedInterval(Vec3(0.01, 0.03, 0.04));
  const GnssAtTime gnss{Vec3(20.0, -1.0, 0.5), Vec3(2.0, 1.5, 1.0), Vec3(0.3, -0.2, 1.1)};
  const Delayed<GnssAtTime> delayed{gnss, Vec3(1.5, -0.8, 0.3), Vec3(0.2, -0.1, 0.6)};
  const std::unique_ptr<ceres::CostFunction> plain(PreintAttachedFactor<GnssAtTime>::Create(s.preint, s.earth, gnss));
  const std::unique_ptr<ceres::CostFunction> late(DelayedAttachedCostFunction<GnssAtTime>::Create(s.preint, s.earth,
                                                                                                  delayed));
  const double zero = 0.0;
  Vec3 r_plain, r_late;
  const double* p3[] = {s.pose_i.data(), s.vel_i.data(), s.bias.data()};
  const double* p4[] = {s.pose_i.data(), s.vel_i.data(), s.bias.data(), &zero};
  ASSERT_TRUE(plain->Evaluate(p3, r_plain.data(), nullptr));
  ASSERT_TRUE(late->Evaluate(p4, r_late.data(), nullptr));
  EXPECT_LT((r_plain - r_late).norm(), 1e-12 * r_plain.norm());

  const std::unique_ptr<ceres::CostFunction> at_kf(GnssFactor::Create(gnss.z_w, gnss.inv_sigma.cwiseInverse(),
                                                                      gnss.lever_b));
  const std::unique_ptr<ceres::CostFunction> late_kf(DelayedAtKeyframeFactor<GnssAtTime>::Create(delayed));
  const double* q1[] = {s.pose_i.data()};
  const double* q3[] = {s.pose_i.data(), s.vel_i.data(), &zero};
  ASSERT_TRUE(at_kf->Evaluate(q1, r_plain.data(), nullptr));
  ASSERT_TRUE(late_kf->Evaluate(q3, r_late.data(), nullptr));
  EXPECT_LT((r_plain - r_late).norm(), 1e-12 * r_plain.norm());
}

TEST(DelayedFactorTest, AFixTakenBeforeItsStampFitsAtItsOffset) {
  // A body at constant velocity, not turning: the antenna was at p − v·τ when the record stamped now was made.
  const Vec3 p(100.0, 50.0, 2.0), v(12.0, -5.0, 0.2), lever(0.3, -0.2, 1.1);
  const Quat q = ExpQuat<double>(Vec3(0.0, 0.0, 0.7));
  const double tau = 0.12;
  const Vec3 sigma(0.02, 0.02, 0.05);
  const Vec3 z = p - v * tau + q * lever;
  const test::PoseBlock pose = test::MakePose(p, q);
  const std::unique_ptr<ceres::CostFunction> f(DelayedAtKeyframeFactor<GnssAtTime>::Create(
      Delayed<GnssAtTime>{GnssAtTime{z, sigma.cwiseInverse(), lever}, Vec3::Zero(), Vec3::Zero()}));
  Vec3 r;
  for (const double td : {tau, 0.0}) {
    const double* params[] = {pose.data(), v.data(), &td};
    ASSERT_TRUE(f->Evaluate(params, r.data(), nullptr));
    if (td == tau) {
      EXPECT_LT(r.norm(), 1e-9) << "at the true offset";
    } else {
      // At 0 the residual is the 1.4 m the body moved, in σ.
      EXPECT_NEAR(r.cwiseProduct(sigma).norm(), (v * tau).norm(), 1e-9);
    }
  }
}

}  // namespace
}  // namespace gins
