// The measurement attachers on a window of their own: what each attaches, to which keyframe, and what its
// check after a solve keeps, removes and counts.
#include "solver/smoother_attachers.h"

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <vector>

#include "core/so3.h"
#include "window_test_util.h"

namespace gins {
namespace {

class AttacherTest : public ::testing::Test {
 protected:
  AttacherTest() : problem_(test::SmootherProblemOptions()), store_(options_), context_{store_, g_w_, last_imu_} {
    options_.gnss.lever_b = Vec3::Zero();
    store_.Reset(&problem_);
  }
  // A keyframe at t, level with yaw 0 (body x east), moving at `speed` along x.
  Keyframe& Push(double t, double speed) {
    NavState x;
    x.t = t;
    x.p_wb = Vec3(10.0 * t, 0.0, 0.0);
    x.v_w = Vec3(speed, 0.0, 0.0);
    return store_.Push(store_.Make(t, x));
  }
  int Residuals() const { return problem_.NumResidualBlocks(); }
  double SquaredResidual(ceres::ResidualBlockId id) {
    double cost = 0.0;
    VecX r(problem_.GetCostFunctionForResidualBlock(id)->num_residuals());
    problem_.EvaluateResidualBlock(id, false, &cost, r.data(), nullptr);
    return r.squaredNorm();
  }
  nlohmann::json Stats(const MeasurementAttacher& a) const {
    nlohmann::json j;
    a.AddStats(&j);
    return j;
  }

  EstimatorOptions options_ = test::WindowOptions(true);
  ceres::Problem problem_;
  KeyframeStore store_;
  Vec3 g_w_ = GravityWorld(9.81);
  std::optional<ImuSample> last_imu_;
  AttachContext context_;
};

WheelMeasurement Wheel(double t, double speed) {
  WheelMeasurement w;
  w.t = t;
  w.speed = speed;
  w.sigma = 0.05;
  w.interval = 0.1;
  return w;
}

TEST_F(AttacherTest, WheelGoesOnceToTheNewestKeyframeWithinTheReadingsInterval) {
  options_.wheel.nonholonomic = true;
  WheelAttacher wheel(options_);
  Push(10.0, 3.0);
  wheel.OnWheel(Wheel(10.05, 3.0), context_);  // interval (9.95, 10.05]: mid-time 10.0
  EXPECT_EQ(Residuals(), 2);                   // speed and NHC
  wheel.OnWheel(Wheel(10.06, 3.0), context_);
  EXPECT_EQ(Residuals(), 2);  // once per keyframe
  Keyframe& far = Push(10.5, 3.0);
  wheel.OnKeyframeCreated(far, context_);  // the last reading is 0.49 s before it
  EXPECT_EQ(Residuals(), 2);
  wheel.OnWheel(Wheel(10.52, 3.0), context_);
  EXPECT_EQ(Residuals(), 4);
  EXPECT_EQ(Stats(wheel)["wheel"]["used"], 2);

  options_.wheel.enabled = false;
  WheelAttacher off(options_);
  off.OnKeyframeCreated(Push(11.0, 3.0), context_);
  off.OnWheel(Wheel(11.0, 3.0), context_);
  EXPECT_EQ(Residuals(), 4);
}

TEST_F(AttacherTest, WheelSpeedIsMovedToTheKeyframesTimeWithTheForwardAcceleration) {
  WheelAttacher wheel(options_);
  Push(10.0, 3.0);
  // Accelerating forward at 2 m/s²: the mean over (9.95, 10.15], at its mid-time 10.05, was 0.1 m/s faster
  // than the speed at 10.0.
  ImuSample imu;
  imu.t = 10.0;
  imu.acc = Vec3(2.0, 0.0, 9.81);
  last_imu_ = imu;
  WheelMeasurement w = Wheel(10.15, 3.1);
  w.interval = 0.2;
  wheel.OnWheel(w, context_);
  std::vector<ceres::ResidualBlockId> ids;
  problem_.GetResidualBlocks(&ids);
  ASSERT_EQ(ids.size(), 1u);
  EXPECT_LT(SquaredResidual(ids[0]), 1e-20);
  // Without the IMU the reading would be taken as the speed at the keyframe.
  last_imu_.reset();
  problem_.RemoveResidualBlock(ids[0]);
  Push(10.5, 3.0);
  wheel.OnWheel(Wheel(10.55, 3.2), context_);
  problem_.GetResidualBlocks(&ids);
  ASSERT_EQ(ids.size(), 1u);
  EXPECT_NEAR(SquaredResidual(ids[0]), (0.2 / 0.05) * (0.2 / 0.05), 1e-9);
}

StandstillMeasurement Standstill(double since, double t) { return {t, since}; }

TEST_F(AttacherTest, ZeroVelocityOnAStandingKeyframeNotOnAMovingOne) {
  StandstillAttacher standstill(options_);
  Push(10.0, 0.01);
  standstill.OnStandstill(Standstill(9.0, 10.0), context_);
  EXPECT_EQ(Residuals(), 1);
  standstill.OnStandstill(Standstill(9.0, 10.1), context_);
  EXPECT_EQ(Residuals(), 1);  // once per keyframe
  Keyframe& late = Push(10.5, 0.01);
  standstill.OnKeyframeCreated(late, context_);  // the last detection (10.1) is too old for 10.5
  EXPECT_EQ(Residuals(), 1);
  Push(11.0, 2.0);  // above standstill.max_speed_m_s
  standstill.OnStandstill(Standstill(10.0, 11.0), context_);
  EXPECT_EQ(Residuals(), 1);
  EXPECT_EQ(Stats(standstill)["zero_velocity"]["rejected"]["moving"], 1);
}

TEST_F(AttacherTest, StandstillCheckJoinsConfirmedKeyframesAndDropsContradictedOnes) {
  StandstillAttacher standstill(options_);
  Keyframe& a = Push(10.0, 0.0);
  standstill.OnStandstill(Standstill(9.0, 10.0), context_);
  Keyframe& b = Push(10.5, 0.0);
  standstill.OnStandstill(Standstill(9.0, 10.5), context_);
  Keyframe& c = Push(11.0, 0.0);
  standstill.OnStandstill(Standstill(9.0, 11.0), context_);
  ASSERT_EQ(Residuals(), 3);
  // The solve said c moves after all: its zero velocity goes; a and b stand, joined by a zero motion.
  c.block(BlockType::kVelocity)[0] = 1.0;
  EXPECT_TRUE(standstill.AfterSolve(context_));
  EXPECT_EQ(Residuals(), 3);  // 3 zero velocities - 1 + 1 zero motion
  EXPECT_FALSE(a.still_from_prev);
  EXPECT_TRUE(b.still_from_prev);
  EXPECT_FALSE(c.still_from_prev);
  const nlohmann::json stats = Stats(standstill);
  EXPECT_EQ(stats["zero_velocity"]["used"], 2);
  EXPECT_EQ(stats["zero_velocity"]["rejected"]["chi2_gate"], 1);
  EXPECT_EQ(stats["zero_motion_factors"], 1);
  EXPECT_FALSE(standstill.AfterSolve(context_));  // each checked once
  EXPECT_EQ(Residuals(), 3);
}

GnssMeasurement Fix(double t, const Vec3& p_w, bool heading) {
  GnssMeasurement m;
  m.t = t;
  m.p_w = p_w;
  m.sigma_w = Vec3(0.05, 0.05, 0.1);
  m.heading_valid = heading;
  m.yaw_G = 0.3;
  m.sigma_yaw = 0.01;
  return m;
}

TEST_F(AttacherTest, GnssAttachesPositionAndHeadingOncePerKeyframe) {
  std::vector<std::pair<double, bool>> checked;
  GnssAttacher gnss(options_, [&](double t, bool accepted) { checked.emplace_back(t, accepted); });
  Keyframe& kf = Push(10.0, 3.0);
  EXPECT_TRUE(gnss.OnGnss(Fix(10.0, kf.State().p_wb, true), context_));
  EXPECT_EQ(Residuals(), 2);
  EXPECT_FALSE(gnss.OnGnss(Fix(10.0, kf.State().p_wb, true), context_));  // one fix per epoch
  EXPECT_EQ(Residuals(), 2);
  Keyframe& next = Push(10.5, 3.0);
  options_.gnss.use_heading = false;
  GnssAttacher no_heading(options_, [](double, bool) {});
  EXPECT_TRUE(no_heading.OnGnss(Fix(10.5, next.State().p_wb, true), context_));
  EXPECT_EQ(Residuals(), 3);
  EXPECT_EQ(Stats(gnss)["gnss_heading"]["used"], 1);
  EXPECT_TRUE(checked.empty());
}

TEST_F(AttacherTest, GnssCheckKeepsAGoodFixAndRemovesAnOutlier) {
  std::vector<std::pair<double, bool>> checked;
  GnssAttacher gnss(options_, [&](double t, bool accepted) { checked.emplace_back(t, accepted); });
  Keyframe& good = Push(10.0, 3.0);
  gnss.OnGnss(Fix(10.0, good.State().p_wb + Vec3(0.02, -0.03, 0.05), false), context_);
  EXPECT_FALSE(gnss.AfterSolve(context_));
  EXPECT_EQ(Residuals(), 1);
  Keyframe& bad = Push(10.5, 3.0);
  gnss.OnGnss(Fix(10.5, bad.State().p_wb + Vec3(3.0, 0.0, 0.0), false), context_);
  EXPECT_EQ(Residuals(), 2);
  EXPECT_TRUE(gnss.AfterSolve(context_));  // removed: solve again
  EXPECT_EQ(Residuals(), 1);
  EXPECT_FALSE(gnss.AfterSolve(context_));  // checked once
  EXPECT_EQ(checked, (std::vector<std::pair<double, bool>>{{10.0, true}, {10.5, false}}));
  const nlohmann::json stats = Stats(gnss);
  EXPECT_EQ(stats["gnss_position"]["used"], 1);
  EXPECT_EQ(stats["gnss_position"]["rejected"]["chi2_gate"], 1);
}

// A new measurement type is a new attacher: the interface's defaults leave everything else alone.
class CountingAttacher final : public MeasurementAttacher {
 public:
  void OnKeyframeCreated(Keyframe& /*kf*/, const AttachContext& /*ctx*/) override { ++created; }
  int created = 0;
};

TEST_F(AttacherTest, InterfaceDefaultsDoNothing) {
  CountingAttacher a;
  Keyframe& kf = Push(10.0, 3.0);
  EXPECT_FALSE(a.OnGnss(Fix(10.0, Vec3::Zero(), true), context_));
  a.OnWheel(Wheel(10.0, 1.0), context_);
  a.OnStandstill(Standstill(9.0, 10.0), context_);
  a.OnKeyframeCreated(kf, context_);
  EXPECT_FALSE(a.AfterSolve(context_));
  EXPECT_EQ(a.created, 1);
  EXPECT_EQ(Residuals(), 0);
  EXPECT_TRUE(Stats(a).is_null());
}

}  // namespace
}  // namespace gins
