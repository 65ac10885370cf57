// The estimators' shared bookkeeping (solver/estimator_common.h).
#include "solver/estimator_common.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/chi2.h"
#include "core/so3.h"

namespace gins {
namespace GINS_TEST_FILE {

TEST(MeasurementCounts, OfferedIsUsedPlusEveryRejection) {
  MeasurementCounts c;
  c.used = 7;
  c.Reject("chi2_gate", 1.0);
  c.Reject("chi2_gate", 2.0);
  c.Reject("numerical", 3.0);
  const nlohmann::json j = c.ToJson();
  EXPECT_EQ(j["used"].get<uint64_t>(), 7u);
  EXPECT_EQ(j["rejected"]["chi2_gate"].get<uint64_t>(), 2u);
  EXPECT_EQ(j["rejected"]["numerical"].get<uint64_t>(), 1u);
  EXPECT_EQ(j["offered"].get<uint64_t>(), 10u);
  EXPECT_EQ(j["rejected_times"].size(), 3u);
  EXPECT_EQ(MeasurementCounts().ToJson()["offered"].get<uint64_t>(), 0u);
}

// χ²(3) draws scaled by `spread` (the innovations' true covariance over the stated one), each accepted only
// under the consistency's current gate as an estimator does, and added to it.
int FeedConsistency(GateConsistency* c, double spread, int n, double gate, std::mt19937* rng, int* raised) {
  std::chi_squared_distribution<double> chi2(3.0);
  int accepted = 0;
  for (int i = 0; i < n; ++i) {
    const double x = spread * chi2(*rng);
    if (x > gate * c->scale()) continue;
    c->Add(x);
    ++accepted;
    if (c->scale() > 1.0) ++*raised;
  }
  return accepted;
}

// The bound on the sample median: disjoint windows of 21 consistent fixes pass it with the gate's
// probability (0.99 here, so that 20000 windows measure it to ±7 %).
TEST(GateConsistency, ConsistentFixesRaiseTheGateAtTheGatesFalseAlarmRate) {
  std::mt19937 rng(7);
  const double gate = Chi2Gate(0.99, 3);
  int raised_windows = 0;
  const int windows = 20000;
  const GateConsistency fresh(0.99, 3);
  for (int w = 0; w < windows; ++w) {
    GateConsistency c = fresh;
    std::chi_squared_distribution<double> chi2(3.0);
    for (int i = 0; i < 21; ++i) c.Add(std::min(chi2(rng), gate));  // the gate truncates
    raised_windows += c.scale() > 1.0;
  }
  const double rate = static_cast<double>(raised_windows) / windows;
  std::printf("consistent windows raised: %.4f (expected at most 0.01)\n", rate);
  EXPECT_GT(rate, 0.006);  // a bound far too high would never raise it
  EXPECT_LT(rate, 0.012);
}

// At the config's default probability, a long run of consistent fixes leaves the gate alone (the scale is
// exactly 1, so every output stays as it was), and fewer than 21 fixes never change it.
TEST(GateConsistency, ConsistentFixesLeaveTheDefaultGateAlone) {
  std::mt19937 rng(11);
  GateConsistency c(0.9999, 3);
  int raised = 0;
  FeedConsistency(&c, 1.0, 20, Chi2Gate(0.9999, 3), &rng, &raised);
  EXPECT_EQ(c.scale(), 1.0);
  FeedConsistency(&c, 1.0, 20000, Chi2Gate(0.9999, 3), &rng, &raised);
  EXPECT_LE(raised, 20);  // of 20000 (overlapping windows: a false alarm lasts a few fixes)
  EXPECT_EQ(GateConsistency(0.0, 3).scale(), 1.0);
}

// Innovations four times the stated σ (χ² 16 times its size): the gate learns a scale near 16 within a few
// dozen fixes, from the fixes it accepted at the stated gate, and then accepts almost all of them.
TEST(GateConsistency, InnovationsWiderThanStatedScaleTheGate) {
  std::mt19937 rng(3);
  const double gate = Chi2Gate(0.9999, 3);
  GateConsistency c(0.9999, 3);
  int raised = 0;
  FeedConsistency(&c, 16.0, 100, gate, &rng, &raised);
  EXPECT_GT(c.scale(), 10.0);
  const int accepted = FeedConsistency(&c, 16.0, 1000, gate, &rng, &raised);
  std::printf("scale %.1f (max %.1f), accepted %d of 1000\n", c.scale(), c.max_scale(), accepted);
  EXPECT_GT(c.scale(), 12.0);
  EXPECT_LT(c.scale(), 21.0);
  EXPECT_GT(accepted, 980);
}

// One accepted fix in ten just inside the gate (multipath the gate cannot tell) barely moves the median:
// the gate is seldom widened for them, and then by little.
TEST(GateConsistency, NearGateOutliersBarelyWidenTheGate) {
  std::mt19937 rng(5);
  std::chi_squared_distribution<double> chi2(3.0);
  const double gate = Chi2Gate(0.9999, 3);
  GateConsistency c(0.9999, 3);
  int raised = 0;
  for (int i = 0; i < 5000; ++i) {
    c.Add(i % 10 == 0 ? 0.95 * gate : std::min(chi2(rng), gate));
    raised += c.scale() > 1.0;
  }
  std::printf("raised on %d of 5000 fixes, max scale %.2f\n", raised, c.max_scale());
  EXPECT_LT(raised, 100);
  EXPECT_LT(c.max_scale(), 3.0);
}

// The watchdog's re-initialisation from a fix (ResetPositionFromFix, ResetWaitsForCourse).
class FixResetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    sensors_.gnss.lever_b = Vec3(-0.17, -0.20, 0.3);
    sensors_.gnss.mount_yaw = 12.0 * kDegToRad;
    sensors_.gnss.use_heading = true;
    sensors_.vehicle.nonholonomic = true;
    // Level but for a small roll, yaw 0, the velocity of a minute ago along the body axis.
    x_.q_wb = Quat(Eigen::AngleAxisd(0.02, Vec3::UnitX()));
    x_.v_w = Vec3(5.0, 0.0, 0.0);
    P_ = MatX::Identity(15, 15) * 1e-4;
    fix_.t = 100.0;
    fix_.p_w = Vec3(10.0, 20.0, 1.0);
    fix_.sigma_w = Vec3(0.02, 0.02, 0.03);
    prev_ = fix_;
    prev_.t = 99.0;
    prev_.p_w = fix_.p_w - Vec3(0.0, 10.0, 0.0);  // 10 m/s due north
  }
  // The yaw's 1-σ (about world up) in P.
  double YawSigma(const NavState& x, const MatX& P) const {
    const Vec3 z_b = x.q_wb.conjugate() * Vec3::UnitZ();
    return std::sqrt(z_b.dot(P.block<3, 3>(nav::kTheta, nav::kTheta) * z_b));
  }
  void LoseYaw(double sigma) { P_.block<3, 3>(nav::kTheta, nav::kTheta).diagonal() << 1e-4, 1e-4, sigma * sigma; }
  SensorOptions sensors_;
  WatchdogOptions watchdog_;
  NavState x_;
  MatX P_;
  GnssMeasurement fix_, prev_;
};

TEST_F(FixResetTest, LostYawComesFromTheDualAntennaHeading) {
  LoseYaw(1.0);
  fix_.heading_valid = true;
  fix_.yaw_G = 1.0 + sensors_.gnss.mount_yaw;
  fix_.sigma_yaw = 0.2 * kDegToRad;
  const FixReset r = ResetPositionFromFix(fix_, std::nullopt, sensors_, watchdog_, &x_, P_);
  EXPECT_STREQ(r.yaw, "heading");
  EXPECT_FALSE(r.velocity_from_fixes);
  EXPECT_NEAR(YawOfXAxis<double>(x_.R_wb()), 1.0, 1e-12);
  EXPECT_NEAR((x_.q_wb.conjugate() * Vec3::UnitZ()).y(), std::sin(0.02), 1e-12);  // the roll is kept
  EXPECT_NEAR(YawSigma(x_, P_), 2.0 * kDegToRad, 1e-9);  // the heading's σ, raised to the 2° floor
  EXPECT_LT((x_.v_w - Vec3(5.0 * std::cos(1.0), 5.0 * std::sin(1.0), 0.0)).norm(), 1e-12);  // turned with it
  EXPECT_LT((x_.p_wb + x_.q_wb * sensors_.gnss.lever_b - fix_.p_w).norm(), 1e-12);  // the arm at the new yaw
  EXPECT_TRUE(Eigen::SelfAdjointEigenSolver<MatX>(P_).eigenvalues().minCoeff() > 0.0);
}

TEST_F(FixResetTest, LostYawOfACarComesFromTheCourseOfTwoFixes) {
  LoseYaw(1.0);
  const FixReset r = ResetPositionFromFix(fix_, prev_, sensors_, watchdog_, &x_, P_);
  EXPECT_STREQ(r.yaw, "course");
  EXPECT_TRUE(r.velocity_from_fixes);
  EXPECT_NEAR(YawOfXAxis<double>(x_.R_wb()), 0.5 * M_PI, 1e-12);
  EXPECT_LT((x_.v_w - Vec3(0.0, 10.0, 0.0)).norm(), 1e-12);
  EXPECT_NEAR(YawSigma(x_, P_), 2.0 * kDegToRad, 1e-9);  // course σ 0.028/10 rad, raised to the floor
  // Too slow for a course (speed below 3 σ of the fixes' velocity): the yaw is kept, σ capped to the fallback.
  LoseYaw(1.0);
  x_.q_wb = Quat::Identity();
  prev_.p_w = fix_.p_w - Vec3(0.0, 0.05, 0.0);
  EXPECT_STREQ(ResetPositionFromFix(fix_, prev_, sensors_, watchdog_, &x_, P_).yaw, "kept");
  EXPECT_NEAR(YawOfXAxis<double>(x_.R_wb()), 0.0, 1e-12);
}

TEST_F(FixResetTest, AKnownYawIsKept) {
  LoseYaw(10.0 * kDegToRad);  // within 20°: the linearisation holds
  fix_.heading_valid = true;
  fix_.yaw_G = 1.0;
  const FixReset r = ResetPositionFromFix(fix_, prev_, sensors_, watchdog_, &x_, P_);
  EXPECT_STREQ(r.yaw, "kept");
  EXPECT_NEAR(YawOfXAxis<double>(x_.R_wb()), 0.0, 1e-12);
  EXPECT_NEAR(YawSigma(x_, P_), 10.0 * kDegToRad, 1e-4);  // about world up, the body rolled 0.02 rad
  // Lost, but not a car: the course says nothing of the yaw.
  LoseYaw(1.0);
  sensors_.vehicle.nonholonomic = false;
  fix_.heading_valid = false;
  EXPECT_STREQ(ResetPositionFromFix(fix_, prev_, sensors_, watchdog_, &x_, P_).yaw, "kept");
}

TEST_F(FixResetTest, WaitsForTheCourseOnlyWhenALaterFixCanGiveTheYaw) {
  LoseYaw(1.0);
  EXPECT_TRUE(ResetWaitsForCourse(fix_, std::nullopt, sensors_, x_, P_));
  prev_.t = fix_.t - 60.0;  // the fix before the pause is too old for a course
  EXPECT_TRUE(ResetWaitsForCourse(fix_, prev_, sensors_, x_, P_));
  prev_.t = fix_.t - 1.0;  // a recent one gives it now
  EXPECT_FALSE(ResetWaitsForCourse(fix_, prev_, sensors_, x_, P_));
  GnssMeasurement slow = prev_;  // ... unless the car moved too little since for a course within ~20°
  slow.p_w = fix_.p_w - Vec3(0.0, 0.05, 0.0);
  EXPECT_TRUE(ResetWaitsForCourse(fix_, slow, sensors_, x_, P_));
  GnssMeasurement with_heading = fix_;
  with_heading.heading_valid = true;
  EXPECT_FALSE(ResetWaitsForCourse(with_heading, std::nullopt, sensors_, x_, P_));
  sensors_.gnss.use_heading = false;  // a heading the config says not to use does not count
  EXPECT_TRUE(ResetWaitsForCourse(with_heading, std::nullopt, sensors_, x_, P_));
  sensors_.vehicle.nonholonomic = false;
  EXPECT_FALSE(ResetWaitsForCourse(fix_, std::nullopt, sensors_, x_, P_));
  sensors_.vehicle.nonholonomic = true;
  LoseYaw(10.0 * kDegToRad);
  EXPECT_FALSE(ResetWaitsForCourse(fix_, std::nullopt, sensors_, x_, P_));
}

// Metre-level fixes at 5 Hz: the held fix and the next are too close for a course; the wait goes on until
// one is far enough (or 2 s have passed: then the reset keeps the yaw).
TEST_F(FixResetTest, WaitsOnUntilAFixGivesTheCourse) {
  LoseYaw(1.0);
  GnssMeasurement held = fix_;
  held.sigma_w = Vec3(1.0, 1.0, 1.5);
  GnssMeasurement next = held;
  for (const auto& [dt, wait] : {std::pair{0.2, true}, {0.4, true}, {0.8, false}}) {
    next.t = held.t + dt;
    next.p_w = held.p_w + Vec3(10.0 * dt, 0.0, 0.0);  // 10 m/s east; 3 σ of the course needs 0.42 s
    EXPECT_EQ(ResetWaitsForCourse(next, held, sensors_, x_, P_, /*waiting=*/true), wait) << dt;
  }
  next.t = held.t + 2.0;  // stopped: no course in 2 s; the reset keeps the yaw
  next.p_w = held.p_w;
  EXPECT_FALSE(ResetWaitsForCourse(next, held, sensors_, x_, P_, /*waiting=*/true));
  next.t = held.t + 1.9;
  EXPECT_TRUE(ResetWaitsForCourse(next, held, sensors_, x_, P_, /*waiting=*/true));
  next.heading_valid = true;  // a heading ends the wait
  EXPECT_FALSE(ResetWaitsForCourse(next, held, sensors_, x_, P_, /*waiting=*/true));
}

}  // namespace
}  // namespace gins
