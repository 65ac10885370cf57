// The smoother's output: the oldest keyframe's covariance from the window's information, a keyframe's
// estimate with its 1-σ, and the IMU-rate final stream between keyframes.
#include "solver/smoother_output.h"

#include <gtest/gtest.h>

#include <vector>

#include "core/so3.h"
#include "window_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

TEST(SmootherOutput, OldestCovarianceIsTheDenseInverseOfTheWindowInformation) {
  for (bool estimate_scale : {false, true}) {
    test::TestWindow w(4, estimate_scale);
    Mat15 cov = Mat15::Constant(-1.0);
    ASSERT_TRUE(OldestCovariance(w.store, &cov));

    const MatX J = test::DenseJacobian(w.problem.get(), w.store.EstimatedBlocks());
    const MatX C = (J.transpose() * J).inverse();
    const std::vector<int> nav = NavIndexOfTangent(w.store.EstimatedTypes());
    Mat15 want = Mat15::Zero();
    for (size_t i = 0; i < nav.size(); ++i) {
      for (size_t j = 0; j < nav.size(); ++j) {
        if (nav[i] >= 0 && nav[j] >= 0) want(nav[i], nav[j]) = C(i, j);
      }
    }
    // The information spans ~10 orders of magnitude (bias random walks against positions): the two
    // inverses agree to the round-off of that conditioning, relative to the coordinates' σ.
    for (int i = 0; i < 15; ++i) {
      for (int j = 0; j < 15; ++j) {
        EXPECT_NEAR(cov(i, j), want(i, j), 1e-7 * std::sqrt(want(i, i) * want(j, j))) << i << "," << j;
      }
    }
    // Every coordinate got a value, and the marginal of the oldest is tighter than its prior alone.
    EXPECT_GT(cov.diagonal().minCoeff(), 0.0);
    EXPECT_LT(cov(nav::kP, nav::kP), 0.01);
  }
}

// The newest keyframes' joint covariance comes from the trailing blocks of the LDLᵀ factor alone, the
// oldest's from column solves: both equal the dense inverse of the window's information.
TEST(SmootherOutput, WindowCovariancesAreBlocksOfTheDenseInverse) {
  for (bool estimate_scale : {false, true}) {
    test::TestWindow w(5, estimate_scale);
    MatX trailing, oldest;
    ASSERT_TRUE(WindowCovariances(w.store, 2, &trailing, &oldest));
    const MatX J = test::DenseJacobian(w.problem.get(), w.store.EstimatedBlocks());
    const MatX C = (J.transpose() * J).inverse();
    const int n = static_cast<int>(C.rows()), per = n / 5;
    ASSERT_EQ(trailing.rows(), 2 * per);
    ASSERT_EQ(oldest.rows(), per);
    const MatX want_trailing = C.bottomRightCorner(2 * per, 2 * per), want_oldest = C.topLeftCorner(per, per);
    for (int i = 0; i < 2 * per; ++i) {
      for (int j = 0; j < 2 * per; ++j) {
        EXPECT_NEAR(trailing(i, j), want_trailing(i, j), 1e-7 * std::sqrt(want_trailing(i, i) * want_trailing(j, j)))
            << i << "," << j;
      }
    }
    for (int i = 0; i < per; ++i) {
      for (int j = 0; j < per; ++j) {
        EXPECT_NEAR(oldest(i, j), want_oldest(i, j), 1e-7 * std::sqrt(want_oldest(i, i) * want_oldest(j, j)))
            << i << "," << j;
      }
    }
    // Without the oldest: the trailing block alone, the same.
    MatX trailing_only;
    ASSERT_TRUE(WindowCovariances(w.store, 1, &trailing_only, nullptr));
    EXPECT_LT((trailing_only - trailing.bottomRightCorner(per, per)).cwiseAbs().maxCoeff(),
              1e-9 * trailing.diagonal().cwiseAbs().maxCoeff());
  }
}

TEST(SmootherOutput, EstimateOfTurnsTheAttitudeSigmaIntoWorldAxes) {
  Keyframe kf;
  NavState x;
  x.t = 3.0;
  x.p_wb = Vec3(1.0, 2.0, 3.0);
  x.q_wb = QuatFromYaw(kPi / 2);  // body x along world y
  kf.t = x.t;
  kf.SetState(x);
  kf.block(BlockType::kScale)[0] = 1.02;
  Mat15 cov = Mat15::Zero();
  cov.diagonal().segment<3>(nav::kP) << 0.01, 0.04, 0.09;
  cov.diagonal().segment<3>(nav::kV) << 1e-4, 4e-4, 9e-4;
  cov.diagonal().segment<3>(nav::kTheta) << 4e-4, 0.0, 0.0;  // about body x only
  const StateEstimate e = EstimateOf(kf, &cov);
  EXPECT_EQ(e.x.t, 3.0);
  EXPECT_EQ(e.odom_scale, 1.02);
  EXPECT_LT((e.sigma_p - Vec3(0.1, 0.2, 0.3)).norm(), 1e-15);
  EXPECT_LT((e.sigma_v - Vec3(0.01, 0.02, 0.03)).norm(), 1e-15);
  EXPECT_NEAR(e.sigma_att.y(), 0.02, 1e-12);
  EXPECT_NEAR(e.sigma_att.x(), 0.0, 1e-9);
  EXPECT_EQ(EstimateOf(kf, nullptr).sigma_p, Vec3::Zero());
}

// Level, unbiased, at constant velocity: the specific force is gravity's reaction and positions follow
// p0 + v·t exactly.
class EmitFinalTest : public ::testing::Test {
 protected:
  EmitFinalTest() {
    NavState x;
    x.t = 10.0;
    x.p_wb = Vec3(1.0, -2.0, 0.5);
    x.v_w = Vec3(2.0, 1.0, 0.0);
    kf_.t = x.t;
    kf_.SetState(x);
    next_.t = x.t + kSteps * kDt;
    ImuSample level;
    level.acc = -g_w_;
    for (int i = 0; i < kSteps; ++i) next_.steps_from_prev.push_back({level, kDt});
  }
  std::vector<StateEstimate> Emit(const Keyframe* next, const std::vector<HeldImuSample>& tail) {
    std::vector<StateEstimate> out;
    EmitFinal(kf_, next, tail, nullptr, g_w_, [&](const StateEstimate& e) { out.push_back(e); });
    return out;
  }
  static constexpr int kSteps = 5;
  static constexpr double kDt = 0.01;
  const Vec3 g_w_ = GravityWorld(9.81);
  Keyframe kf_, next_;
};

TEST_F(EmitFinalTest, ImuRateStatesUpToTheNextKeyframe) {
  const std::vector<StateEstimate> out = Emit(&next_, {});
  ASSERT_EQ(out.size(), static_cast<size_t>(kSteps));  // the keyframe and the steps but the last
  const NavState x0 = kf_.State();
  for (int i = 0; i < kSteps; ++i) {
    EXPECT_NEAR(out[i].x.t, x0.t + i * kDt, 1e-12);
    EXPECT_LT((out[i].x.p_wb - (x0.p_wb + x0.v_w * (i * kDt))).norm(), 1e-12) << i;
    EXPECT_LT((out[i].x.v_w - x0.v_w).norm(), 1e-12) << i;
  }
}

TEST_F(EmitFinalTest, StandingBetweenKeyframesHoldsThePose) {
  next_.still_from_prev = true;
  const std::vector<StateEstimate> out = Emit(&next_, {});
  ASSERT_EQ(out.size(), static_cast<size_t>(kSteps));
  for (size_t i = 1; i < out.size(); ++i) {
    EXPECT_EQ(out[i].x.p_wb, out[0].x.p_wb);
    EXPECT_EQ(out[i].x.v_w, Vec3::Zero());
  }
}

TEST_F(EmitFinalTest, TheNewestKeyframeEmitsItsWholeTail) {
  const std::vector<StateEstimate> out = Emit(nullptr, next_.steps_from_prev);
  ASSERT_EQ(out.size(), static_cast<size_t>(kSteps + 1));
  EXPECT_NEAR(out.back().x.t, kf_.t + kSteps * kDt, 1e-12);
}

}  // namespace
}  // namespace gins
