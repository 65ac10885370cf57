// The IMU's units and axes from its first samples, and the gyro against the GNSS track's turns
// (core/imu_checks.h): each verdict at its bound.
#include "core/imu_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

namespace gins {
namespace GINS_TEST_FILE {

// kSamples of specific force `f` plus white noise σ (m/s²), then the verdict.
ImuAxesAndUnitsCheck::Outcome Judge(const Vec3& f, bool land_vehicle, std::string* message = nullptr) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  ImuAxesAndUnitsCheck check;
  for (size_t k = 0; k < ImuAxesAndUnitsCheck::kSamples; ++k) {
    EXPECT_EQ(check.Judge(land_vehicle), ImuAxesAndUnitsCheck::Outcome::kPending);
    check.Add(f + Vec3(noise(rng), noise(rng), noise(rng)));
  }
  const ImuAxesAndUnitsCheck::Outcome o = check.Judge(land_vehicle);
  if (message) *message = check.message();
  return o;
}

TEST(ImuAxesAndUnitsCheck, GravityUpOrTiltedOrAcceleratingIsOk) {
  using O = ImuAxesAndUnitsCheck::Outcome;
  EXPECT_EQ(Judge(Vec3(0.0, 0.0, 9.81), true), O::kOk);
  EXPECT_EQ(Judge(Vec3(3.0, -2.0, 9.2), true), O::kOk);   // tilted 21°
  EXPECT_EQ(Judge(Vec3(4.9, 0.0, 9.81), true), O::kOk);   // braking at 0.5 g
  EXPECT_EQ(Judge(Vec3(0.0, 9.81, 0.5), true), O::kOk);   // mounted on its side: z not down
}

// A logger's all-zero records at power-up are no evidence of a unit: the check waits for real readings.
TEST(ImuAxesAndUnitsCheck, AllZeroRecordsAtPowerUpAreNotJudged) {
  ImuAxesAndUnitsCheck check;
  for (size_t k = 0; k < 3 * ImuAxesAndUnitsCheck::kSamples; ++k) check.Add(Vec3::Zero());
  EXPECT_EQ(check.Judge(true), ImuAxesAndUnitsCheck::Outcome::kPending);
  for (size_t k = 0; k < ImuAxesAndUnitsCheck::kSamples; ++k) check.Add(Vec3(0.0, 0.0, 9.81));
  EXPECT_EQ(check.Judge(true), ImuAxesAndUnitsCheck::Outcome::kOk);
}

TEST(ImuAxesAndUnitsCheck, AccelerometerInGIsRefusedAndNamed) {
  std::string m;
  EXPECT_EQ(Judge(Vec3(0.0, 0.0, 1.0), true, &m), ImuAxesAndUnitsCheck::Outcome::kRefuse);
  EXPECT_NE(m.find("in g, not m/s²"), std::string::npos) << m;
  // Another unit, or the gyro in the accelerometer's columns: refused, not called g.
  EXPECT_EQ(Judge(Vec3(0.0, 0.0, 981.0), false, &m), ImuAxesAndUnitsCheck::Outcome::kRefuse);
  EXPECT_NE(m.find("another unit"), std::string::npos) << m;
  EXPECT_EQ(Judge(Vec3(0.01, 0.0, 0.02), false, &m), ImuAxesAndUnitsCheck::Outcome::kRefuse);
  EXPECT_EQ(m.find("in g,"), std::string::npos) << m;
}

TEST(ImuAxesAndUnitsCheck, ZDownIsRefusedForACarAndWarnedOtherwise) {
  std::string m;
  EXPECT_EQ(Judge(Vec3(0.0, 0.0, -9.81), true, &m), ImuAxesAndUnitsCheck::Outcome::kRefuse);
  EXPECT_NE(m.find("imu.axes"), std::string::npos) << m;
  EXPECT_EQ(Judge(Vec3(0.0, 0.0, -9.81), false, &m), ImuAxesAndUnitsCheck::Outcome::kWarn);
  // Steep but not down: within half of g below the horizon is still a possible mount.
  EXPECT_EQ(Judge(Vec3(8.0, 0.0, -4.5), true), ImuAxesAndUnitsCheck::Outcome::kOk);
}

}  // namespace
}  // namespace gins

namespace gins {
namespace GINS_TEST_FILE {

// A car at 10 m/s on 1 Hz fixes (2 cm), level, turning at `rate` (rad/s, true) for 30 s after 10 s straight;
// the gyro reads gyro_scale × the true rate; mirror: the track's north flipped (a mirrored track).
TurnRateCheck::Outcome Drive(double rate, double gyro_scale, bool mirror, TurnRateCheck* check) {
  double yaw = 0.0;
  Vec3 p = Vec3::Zero();
  for (int k = 0; k <= 4000; ++k) {
    const double t = 0.01 * k;
    const double w = t < 10.0 ? 0.0 : rate;
    check->AddImu(t, Vec3(0.0, 0.0, gyro_scale * w), Vec3(0.0, 0.0, 9.81));
    if (k % 100 == 0) check->AddFix(t, Vec3(p.x(), mirror ? -p.y() : p.y(), 0.0), 0.02);
    yaw += w * 0.01;
    p += 10.0 * 0.01 * Vec3(std::cos(yaw), std::sin(yaw), 0.0);
  }
  return check->outcome();
}

TEST(TurnRateCheck, ACarWhoseGyroAndTrackAgreeIsOk) {
  TurnRateCheck check;
  EXPECT_EQ(Drive(0.05, 1.0, false, &check), TurnRateCheck::Outcome::kOk);
  EXPECT_NEAR(check.slope(), 1.0, 0.05);
  // Driving straight says nothing: no verdict.
  TurnRateCheck straight;
  EXPECT_EQ(Drive(0.0, 1.0, false, &straight), TurnRateCheck::Outcome::kPending);
}

TEST(TurnRateCheck, GyroInDegreesPerSecondIsRefusedAndNamed) {
  TurnRateCheck check;
  EXPECT_EQ(Drive(0.05, kRadToDeg, false, &check), TurnRateCheck::Outcome::kRefuse);
  EXPECT_NE(check.message().find("in deg/s"), std::string::npos) << check.message();
}

TEST(TurnRateCheck, AMirroredTrackIsRefusedAndNamed) {
  TurnRateCheck check;
  EXPECT_EQ(Drive(0.05, 1.0, true, &check), TurnRateCheck::Outcome::kRefuse);
  EXPECT_NE(check.message().find("latitude and longitude swapped"), std::string::npos) << check.message();
  // A gyro 2× off (another unit) is not a mistake the check can name: it keeps watching.
  TurnRateCheck other;
  EXPECT_EQ(Drive(0.05, 2.0, false, &other), TurnRateCheck::Outcome::kPending);
}

// A car at 10 m/s, straight for 10 s, then turning at `rate`, with 1 Hz RTK fixes and a dual-antenna
// heading mounted at `mount` (true), logged in degrees or, by mistake, in radians; the check is told
// `configured_mount`.
HeadingCourseCheck::Outcome HeadingDrive(double rate, bool in_radians, double mount, double configured_mount,
                                         HeadingCourseCheck* check) {
  double yaw = 0.3;
  Vec3 p = Vec3::Zero();
  for (int k = 0; k <= 6000; ++k) {
    const double t = 0.01 * k;
    if (k % 100 == 0) {
      double heading_deg = 90.0 - (yaw + mount) * kRadToDeg;  // compass, clockwise from north
      heading_deg = std::fmod(heading_deg + 720.0, 360.0);
      check->AddFix(t, p, 0.02, in_radians ? heading_deg * kDegToRad : heading_deg, configured_mount);
    }
    yaw += (t < 10.0 ? 0.0 : rate) * 0.01;
    p += 10.0 * 0.01 * Vec3(std::cos(yaw), std::sin(yaw), 0.0);
  }
  return check->outcome();
}

TEST(HeadingCourseCheck, AHeadingThatFollowsTheCourseIsOk) {
  HeadingCourseCheck check;
  EXPECT_EQ(HeadingDrive(0.05, false, 0.21, 0.21, &check), HeadingCourseCheck::Outcome::kOk);
  HeadingCourseCheck straight;
  EXPECT_EQ(HeadingDrive(0.0, false, -1.2, -1.2, &straight), HeadingCourseCheck::Outcome::kOk);
}

TEST(HeadingCourseCheck, HeadingsInRadiansAreRefusedAndNamed) {
  for (const double rate : {0.0, 0.05}) {
    HeadingCourseCheck check;
    EXPECT_EQ(HeadingDrive(rate, true, 0.21, 0.21, &check), HeadingCourseCheck::Outcome::kRefuse) << rate;
    EXPECT_NE(check.message().find("in radians, not degrees"), std::string::npos) << check.message();
  }
}

TEST(HeadingCourseCheck, AWrongMountAngleIsRefusedWithTheOffsetMeasured) {
  HeadingCourseCheck check;
  EXPECT_EQ(HeadingDrive(0.05, false, 0.21, 0.21 + 30.0 * kDegToRad, &check), HeadingCourseCheck::Outcome::kRefuse);
  EXPECT_NE(check.message().find("gnss.mount_yaw_deg (42.03) should be about 12.0"), std::string::npos)
      << check.message();
  // A mount within the tolerance (a few degrees: the heading update itself handles it) is not refused.
  // On a straight road a constant offset may be a stuck heading as well: not refused without turns.
  HeadingCourseCheck straight;
  EXPECT_EQ(HeadingDrive(0.0, false, 0.21, 0.21 + 30.0 * kDegToRad, &straight), HeadingCourseCheck::Outcome::kPending);
  HeadingCourseCheck close;
  EXPECT_EQ(HeadingDrive(0.05, false, 0.21, 0.21 + 3.0 * kDegToRad, &close), HeadingCourseCheck::Outcome::kOk);
}

}  // namespace
}  // namespace gins
