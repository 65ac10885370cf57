// The measurement attachers on a window of their own, with the smoother's services stubbed: what each
// checks against the prediction, what it attaches and where (a keyframe of its epoch or through the IMU
// preintegrated from the newest keyframe), and what it counts.
#include "solver/smoother_attachers.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "core/so3.h"
#include "solver/vehicle_attacher.h"
#include "window_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

class AttacherTest : public ::testing::Test {
 protected:
  AttacherTest()
      : problem_(test::SmootherProblemOptions()),
        store_(sensors_),
        context_{store_,
                 earth_,
                 last_imu_,
                 [this](double t) { return Predict(t); },
                 [this](double t) { return Anchor(t); },
                 [this]() -> const MatX* { return two_.size() > 0 ? &two_ : nullptr; },
                 [this](double t) { return Anchor(t); },
                 [this](double t) { return Predict(t).x; },
                 [this](double t) { return Anchor(t); }} {
    sensors_.gnss.lever_b = Vec3::Zero();
    sensors_.wheel.lever_b = Vec3::Zero();
    store_.Reset(&problem_);
  }
  // A keyframe at t, level with yaw 0 (body x east), moving at `speed` along x from x = 10·t.
  Keyframe& Push(double t, double speed) {
    NavState x;
    x.t = t;
    x.p_wb = Vec3(10.0 * t, 0.0, 0.0);
    x.v_w = Vec3(speed, 0.0, 0.0);
    Keyframe& kf = store_.Push(store_.Make(t, x));
    return kf;
  }
  // IMU steps over `span` s at 100 Hz reading a rate `rate_z` about body z (no bias, no Earth rate here).
  static std::vector<HeldImuSample> Steps(double rate_z, double span) {
    std::vector<HeldImuSample> steps;
    for (int k = 0; k < static_cast<int>(std::lround(span / 0.01)); ++k) {
      HeldImuSample h;
      h.sample.gyro = Vec3(0.0, 0.0, rate_z);
      h.dt = 0.01;
      steps.push_back(h);
    }
    return steps;
  }
  // The prediction stub: the newest keyframe, with a diagonal covariance of position σ_p.
  Prediction Predict(double /*t*/) {
    Prediction p;
    p.x = store_.back().State();
    const int n = static_cast<int>(NavIndexOfTangent(store_.EstimatedTypes()).size());
    p.cov = MatX::Identity(n, n) * 1e-6;
    p.cov.topLeftCorner<3, 3>() = Mat3::Identity() * sigma_p_ * sigma_p_;
    return p;
  }
  // The anchor stub: the newest keyframe at its epoch, else (when allowed) a new keyframe at t.
  gins::Anchor Anchor(double t) {
    ++anchors_;
    if (std::abs(t - store_.back().t) < 1e-6) return {&store_.back(), nullptr};
    return {&Push(t, 10.0), nullptr};
  }
  int Residuals() const { return problem_.NumResidualBlocks(); }
  nlohmann::json Stats(const MeasurementAttacher& a) const {
    nlohmann::json j;
    a.AddStats(&j);
    return j;
  }

  SensorOptions sensors_ = test::WindowSensors(true);
  StandstillOptions standstill_options_;
  ceres::Problem problem_;
  KeyframeStore store_;
  EarthModel earth_ = EarthModel(9.81);
  std::optional<ImuSample> last_imu_;
  double sigma_p_ = 0.05;
  MatX two_;
  int anchors_ = 0;
  AttachContext context_;
};

GnssMeasurement Fix(double t, const Vec3& p_w) {
  GnssMeasurement m;
  m.t = t;
  m.p_w = p_w;
  m.sigma_w = Vec3::Constant(0.02);
  return m;
}

TEST_F(AttacherTest, GnssFixIsCheckedAgainstThePredictionAndAttachedAtItsEpoch) {
  Push(10.0, 10.0);  // at (100, 0, 0), σ_p 5 cm
  std::vector<std::pair<double, bool>> outcomes;
  GnssAttacher gnss(sensors_.gnss, [&](double t, bool ok) { outcomes.emplace_back(t, ok); }, [](double) {});
  // 10 cm off: innovation χ² ≈ 0.1²/(0.05² + 0.02²) ≈ 3.4: accepted, at full weight.
  EXPECT_TRUE(gnss.On(Fix(10.0, Vec3(100.1, 0.0, 0.0)), context_));
  EXPECT_EQ(Residuals(), 1);
  // 1 m off: χ² ≈ 345, far beyond the 3-dof gate (21.1): rejected, nothing attached.
  EXPECT_FALSE(gnss.On(Fix(10.0, Vec3(101.0, 0.0, 0.0)), context_));
  EXPECT_EQ(Residuals(), 1);
  // The same 1 m with a window that is itself uncertain to 2 m (after an outage): accepted. A check with R
  // alone would have rejected it.
  sigma_p_ = 2.0;
  EXPECT_TRUE(gnss.On(Fix(10.0, Vec3(101.0, 0.0, 0.0)), context_));
  EXPECT_EQ(Residuals(), 2);
  ASSERT_EQ(outcomes.size(), 3u);
  EXPECT_TRUE(outcomes[0].second);
  EXPECT_FALSE(outcomes[1].second);
  EXPECT_TRUE(outcomes[2].second);
  const nlohmann::json s = Stats(gnss);
  EXPECT_EQ(s["gnss_position"]["used"], 2);
  EXPECT_EQ(s["gnss_position"]["rejected"]["chi2_gate"], 1);
}

TEST_F(AttacherTest, AgreeingRejectedFixesReacquire) {
  Push(0.0, 10.0);
  sigma_p_ = 0.02;
  std::vector<double> reacquired;
  GnssAttacher gnss(sensors_.gnss, [](double, bool) {}, [&](double f) { reacquired.push_back(f); });
  // The estimate is 0.5 m off (an overconfident window after an outage): every fix agrees with the next.
  int accepted_at = -1;
  for (int k = 0; k < 10 && accepted_at < 0; ++k) {
    if (gnss.On(Fix(0.0 + k, Vec3(0.5, 0.0, 0.0) + store_.back().State().p_wb), context_)) accepted_at = k;
  }
  EXPECT_GT(accepted_at, 0);
  EXPECT_LE(accepted_at, 6);  // 2^k doubt: (0.5/0.028)² ≈ 320 over a gate of 21 needs k ≈ 4
  ASSERT_EQ(reacquired.size(), 1u);
  EXPECT_GT(reacquired[0], 1.0);
  EXPECT_EQ(Stats(gnss)["gnss_reacquired"], 1);
}

TEST_F(AttacherTest, ScatteredOutliersDoNotReacquire) {
  Push(0.0, 10.0);
  sigma_p_ = 0.02;
  GnssAttacher gnss(sensors_.gnss, [](double, bool) {}, [](double) {});
  // 20 m outliers in directions that change every time: never a run that agrees.
  for (int k = 0; k < 12; ++k) {
    const double a = 2.1 * k;
    EXPECT_FALSE(gnss.On(Fix(k, store_.back().State().p_wb + 20.0 * Vec3(std::cos(a), std::sin(a), 0.0)),
                             context_));
  }
  EXPECT_EQ(Stats(gnss)["gnss_reacquired"], 0);
}

TEST_F(AttacherTest, StandstillIsCheckedAgainstThePredictedVelocity) {
  standstill_options_.max_speed = 0.5;
  StandstillAttacher standstill(standstill_options_, sensors_.imu, sensors_.wheel.gate_probability);
  Keyframe& a = Push(20.0, 0.01);
  standstill.On({20.0, 18.0}, context_);
  EXPECT_EQ(Residuals(), 1);  // the zero velocity
  Keyframe& b = Push(20.5, 0.01);
  b.steps_from_prev = Steps(0.0, 0.5);  // the gyro reads no rotation
  standstill.OnKeyframeCreated(b, context_);
  EXPECT_EQ(Residuals(), 1);  // the last detection (20.0) is too old for it
  standstill.On({20.5, 18.0}, context_);
  EXPECT_EQ(Residuals(), 3);  // its zero velocity and the zero motion from a
  EXPECT_TRUE(b.still_from_prev);
  (void)a;
  // A "standstill" the prediction contradicts (0.3 m/s with a velocity σ of 1 mm/s) is not taken.
  Keyframe& c = Push(21.0, 0.3);
  standstill.On({21.0, 18.0}, context_);
  EXPECT_EQ(Residuals(), 3);
  (void)c;
  const nlohmann::json s = Stats(standstill);
  EXPECT_EQ(s["zero_velocity"]["used"], 2);
  EXPECT_EQ(s["zero_velocity"]["rejected"]["chi2_gate"], 1);
  EXPECT_EQ(s["zero_motion_factors"], 1);
  EXPECT_EQ(s["zero_rotation"]["used"], 1);
}

// Standing but turning in place: the gyro reads 1.1 deg/s where the bias (σ 0.06 deg/s) and the noise over
// 0.5 s (0.04 deg/s) allow far less. The zero motion joins the keyframes with its rotation free, and the
// outputs between them are not held still.
TEST_F(AttacherTest, StandingButTurningKeepsTheRotationFree) {
  StandstillAttacher standstill(standstill_options_, sensors_.imu, sensors_.wheel.gate_probability);
  Push(20.0, 0.0);
  standstill.On({20.0, 18.0}, context_);
  Keyframe& b = Push(20.5, 0.0);
  b.steps_from_prev = Steps(0.02, 0.5);
  standstill.On({20.5, 18.0}, context_);
  EXPECT_EQ(Residuals(), 3);  // two zero velocities and the zero motion
  EXPECT_FALSE(b.still_from_prev);
  const nlohmann::json s = Stats(standstill);
  EXPECT_EQ(s["zero_motion_factors"], 1);
  EXPECT_EQ(s["zero_rotation"]["rejected"]["chi2_gate"], 1);
  EXPECT_EQ(s["zero_rotation"]["used"], 0);
}

WheelMeasurement Wheel(double t, double speed) {
  WheelMeasurement w;
  w.t = t;
  w.speed = speed;
  w.sigma = 0.05;
  w.interval = 0.1;
  w.distance = speed * 0.1;
  return w;
}

TEST_F(AttacherTest, OdometerIntegratesEveryRecordAndSplitsTheOneAcrossAKeyframe) {
  VehicleAttacher vehicle(sensors_);
  sensors_.vehicle.nonholonomic = false;
  VehicleAttacher odometer_only(sensors_);
  // Keyframes at 0, 1 and 2 s; records every 0.1 s from 0.05 s, so the record at 1.05 s straddles 1.0 s.
  Keyframe& k0 = Push(0.0, 10.0);
  odometer_only.OnKeyframeCreated(k0, context_);
  for (double t = 0.05; t < 1.0; t += 0.1) odometer_only.On(Wheel(t, 10.0), context_);
  Keyframe& k1 = Push(1.0, 10.0);
  odometer_only.OnKeyframeCreated(k1, context_);
  for (double t = 1.05; t < 2.0; t += 0.1) odometer_only.On(Wheel(t, 10.0), context_);
  const int before = Residuals();
  // The joint covariance of k0 and k1 after a "solve".
  const int n = static_cast<int>(NavIndexOfTangent(store_.EstimatedTypes()).size());
  two_ = MatX::Identity(2 * n, 2 * n) * 1e-4;
  Keyframe& k2 = Push(2.0, 10.0);
  odometer_only.OnKeyframeCreated(k2, context_);
  // The interval [0, 1] is closed: 0.95 s of records from 0.05 s... its first record starts at −0.05 s
  // (before k0), so 0.95 s is covered: enough. One odometer factor, at 10 m = 10·1 s... of which the
  // records over (0, 1] give 10·(0.05 + 0.9 + 0.05) = 10 m.
  EXPECT_EQ(Residuals(), before + 1);
  const nlohmann::json s = Stats(odometer_only);
  EXPECT_EQ(s["wheel"]["used"], 1);
  EXPECT_GE(s["wheel"]["records"].get<int>(), 19);
  (void)vehicle;
}

TEST_F(AttacherTest, NonHolonomicConstraintAtEachKeyframeWithOrWithoutWheels) {
  sensors_.wheel.enabled = false;
  VehicleAttacher vehicle(sensors_);
  Keyframe& k0 = Push(0.0, 10.0);
  vehicle.OnKeyframeCreated(k0, context_);
  EXPECT_EQ(Residuals(), 1);  // the NHC at k0
  const int n = static_cast<int>(NavIndexOfTangent(store_.EstimatedTypes()).size());
  two_ = MatX::Identity(2 * n, 2 * n) * 1e-4;
  Keyframe& k1 = Push(1.0, 10.0);
  auto preint = std::make_shared<Preintegration>(Vec3::Zero(), Vec3::Zero(), 1e-3, 1e-2);
  preint->Integrate(Vec3::Zero(), Vec3(0.0, 0.0, 9.81), 1.0);
  k1.preint = preint;
  vehicle.OnKeyframeCreated(k1, context_);
  EXPECT_EQ(Residuals(), 3);  // the chord from k0 and the NHC at k1
  // A keyframe sliding sideways at 2 m/s is rejected by its check (σ 0.1 m/s).
  NavState x = k1.State();
  x.t = 2.0;
  x.v_w = Vec3(10.0, 2.0, 0.0);
  Keyframe& k2 = store_.Push(store_.Make(2.0, x));
  vehicle.OnKeyframeCreated(k2, context_);
  const nlohmann::json s = Stats(vehicle);
  EXPECT_EQ(s["nonholonomic"]["used"], 2);
  EXPECT_EQ(s["nonholonomic"]["rejected"]["chi2_gate"], 1);
}

// The chord between two keyframes is checked across the path the IMU traced (OnImuStep): entering a left turn
// while speeding up, it is used; against a path that went straight on, the same keyframes are rejected.
TEST_F(AttacherTest, ChordFollowsThePathTheImuTraced) {
  sensors_.wheel.enabled = false;
  VehicleAttacher turned(sensors_), straight(sensors_);
  Keyframe& k0 = Push(0.0, 8.0);
  turned.OnKeyframeCreated(k0, context_);
  straight.OnKeyframeCreated(k0, context_);
  const int n = static_cast<int>(NavIndexOfTangent(store_.EstimatedTypes()).size());
  two_ = MatX::Identity(2 * n, 2 * n) * 1e-6;
  const double alpha = 0.6, accel = 1.5, dt = 0.01;  // yaw acceleration rad/s², m/s², IMU step s
  auto yaw = [&](double t) { return 0.5 * alpha * t * t; };
  auto speed = [&](double t) { return 8.0 + accel * t; };
  Vec3 p = Vec3::Zero();
  for (int k = 0; k < 110; ++k) {
    const double t0 = k * dt, t1 = t0 + dt;
    ImuStepView step;
    step.dt = dt;
    step.dR_begin = QuatFromYaw(yaw(t0));
    step.dR_end = QuatFromYaw(yaw(t1));
    step.v_b_begin = Vec3(speed(t0), 0.0, 0.0);
    step.v_b_end = Vec3(speed(t1), 0.0, 0.0);
    step.omega_b = Vec3(0.0, 0.0, alpha * 0.5 * (t0 + t1));
    turned.OnImuStep(step);
    step.dR_begin = step.dR_end = Quat::Identity();
    straight.OnImuStep(step);
    for (int m = 0; m < 10; ++m) {  // the true path, finer
      const double t = t0 + (m + 0.5) * dt / 10.0;
      p += speed(t) * dt / 10.0 * (QuatFromYaw(yaw(t)) * Vec3::UnitX());
    }
  }
  NavState x;
  x.t = 1.1;
  x.p_wb = p;
  x.q_wb = QuatFromYaw(yaw(1.1));
  x.v_w = x.q_wb * Vec3(speed(1.1), 0.0, 0.0);
  Keyframe& k1 = store_.Push(store_.Make(1.1, x));
  auto preint = std::make_shared<Preintegration>(Vec3::Zero(), Vec3::Zero(), 1e-3, 1e-2);
  preint->Integrate(Vec3(0.0, 0.0, 0.33), Vec3(accel, 0.0, 9.81), 1.1);
  k1.preint = preint;
  turned.OnKeyframeCreated(k1, context_);
  straight.OnKeyframeCreated(k1, context_);
  EXPECT_EQ(Stats(turned)["nonholonomic_chord"]["used"], 1);
  EXPECT_EQ(Stats(straight)["nonholonomic_chord"]["rejected"]["chi2_gate"], 1);
}

}  // namespace
}  // namespace gins
