// The Earth's rotation in both estimators (gravity.earth_rotation, core/earth.h): on a rotating-Earth
// simulation with a tactical-grade IMU, a 120 s GNSS outage at 15 m/s. Without the model the drift is
// hundreds of metres: Coriolis alone is 2ω×v ≈ 2e-3 m/s² there (14 m in 120 s), and the Earth rate
// (15 deg/h) the static initialisation takes for gyro bias tilts the platform. With it, what is left is the
// INS's own error: a horizontal gyro bias known to ~1 deg/h after 20 s of standstill (the gyro's angle
// random walk over that time) tilts the platform by ~0.03° in 120 s, g·ε·t³/6 ≈ 14 m.
#include <gtest/gtest.h>

#include "drive_harness.h"
#include "test_scenarios.h"

namespace gins {
namespace GINS_TEST_FILE {

SimOptions TacticalDrive() {
  SimOptions s = test::TestDrive(11);
  const double d = kDegToRad;
  s.segments = {
      {20.0, 0.0, 0.0, 0.0},        // standstill: static initialisation
      {15.0, 1.0, 0.0, 0.0},        // to 15 m/s
      {30.0, 0.0, 0.0, 0.0},        // GNSS still there
      {30.0, 0.0, 3.0 * d, 0.0},    // the outage starts at 70 s: a long left curve
      {40.0, 0.0, 0.0, 0.0},
      {30.0, 0.0, -3.0 * d, 0.0},   // and back
      {20.0, 0.0, 0.0, 0.0},        // GNSS back at 190 s
      {10.0, -1.5, 0.0, 0.0},
  };
  // Tactical grade: 0.05 deg/√h, 0.02 m/s/√h, turn-on biases 1 deg/h and 2e-4 m/s².
  s.gyro_noise_density = 0.05 * d / 60.0;
  s.acc_noise_density = 0.02 / 60.0;
  s.gyro_bias_rw = 0.1 * d / 3600.0 / 60.0;
  s.acc_bias_rw = 1e-4 / 60.0;
  s.gyro_turn_on_bias = 1.0 * d / 3600.0;
  s.acc_turn_on_bias = 2e-4;
  s.wheel_rate = 0.0;
  s.gnss_outages = {{70.0, 120.0}};
  s.earth_rotation = true;
  return s;
}

Options TacticalOptions(const SimOptions& sim, bool earth_rotation) {
  Options o = test::TestRunOptions(sim);
  const double d = kDegToRad;
  o.sensors.imu.gyro_noise_density = 0.05 * d / 60.0;
  o.sensors.imu.acc_noise_density = 0.02 / 60.0;
  o.sensors.imu.gyro_bias_rw = 0.1 * d / 3600.0 / 60.0;
  o.sensors.imu.acc_bias_rw = 1e-4 / 60.0;
  o.sensors.imu.init_gyro_bias_sigma = 2.0 * d / 3600.0;
  o.sensors.imu.init_acc_bias_sigma = 1e-3;
  o.sensors.gravity.earth_rotation = earth_rotation;
  return o;
}

TEST(EarthRotation, TacticalImuThroughA120sOutage) {
  const SimOptions sim = TacticalDrive();
  const test::DriveRun with = test::RunDriveThroughSession(sim, TacticalOptions(sim, true));
  const test::DriveRun without = test::RunDriveThroughSession(sim, TacticalOptions(sim, false));
  ASSERT_TRUE(with.initialized && without.initialized);
  const double t0 = sim.start_time + 70.0, t1 = t0 + 120.0;
  const test::DriveErrors e_on = test::Errors(with, with.eskf, t0, t1);
  const test::DriveErrors e_off = test::Errors(without, without.eskf, t0, t1);
  const test::DriveErrors s_on = test::Errors(with, with.smoother, t0, t1);
  const test::DriveErrors s_off = test::Errors(without, without.smoother, t0, t1);
  test::PrintErrors("eskf, Earth rotation on", e_on);
  test::PrintErrors("eskf, Earth rotation off", e_off);
  test::PrintErrors("smoother, Earth rotation on", s_on);
  test::PrintErrors("smoother, Earth rotation off", s_off);
  EXPECT_LT(e_on.max_h, 30.0);
  EXPECT_LT(s_on.max_h, 30.0);
  EXPECT_GT(e_off.max_h, 5.0 * e_on.max_h);
  EXPECT_GT(s_off.max_h, 5.0 * s_on.max_h);
}

}  // namespace
}  // namespace gins
