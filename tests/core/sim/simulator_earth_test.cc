// The simulator's rotating Earth (simulate.earth_rotation): IMU physics, truth file and heading frames.
#include <GeographicLib/Geodesic.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/earth.h"
#include "core/imu_kernel.h"
#include "core/io/truth_reader.h"
#include "core/sim/simulator.h"
#include "core/so3.h"
#include "sim_test_util.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

using test::FarDrive;
using test::NoiseFreeSim;
using test::OfType;
using test::RunAll;

SimOptions Rotating(SimOptions sim) {
  sim.earth_rotation = true;
  return sim;
}

// At rest the gyro reads the Earth rate alone and the accelerometer the plumb line: at the origin and ~8 km
// away, where the local vertical leans from w's by distance / R.
TEST(SimEarth, AtRestImuReadsEarthRateAndLocalGravity) {
  const SimOptions options = Rotating(NoiseFreeSim(FarDrive()));
  Simulator sim(options);
  const double lat = options.origin.lat_deg * kDegToRad;
  const Vec3 earth_rate_w = kEarthRate * Vec3(0.0, std::cos(lat), std::sin(lat));
  const LocalEnuFrame frame(options.origin);
  int at_origin = 0, far = 0;
  SimRecord r;
  while (sim.Next(&r)) {
    if (!r.is<ImuSample>()) continue;
    const double s = r.get<ImuSample>().t - options.start_time;
    const bool parked = (s > 1.0 && s < 9.0) || (s > 471.0 && s < 483.0);  // FarDrive's standstills
    if (!parked) continue;
    const NavState& x = r.truth;
    ASSERT_LT(x.v_w.norm(), 1e-12) << s;
    EXPECT_LT((x.q_wb * r.get<ImuSample>().gyro - earth_rate_w).norm(), 1e-18) << s;
    EXPECT_NEAR(r.get<ImuSample>().gyro.norm(), kEarthRate, 1e-18) << s;
    const GeodeticPoint g = frame.ToGeodetic(x.p_wb);
    const Vec3 g_w = NormalGravityWorld(frame, x.p_wb);
    EXPECT_LT((r.get<ImuSample>().acc + x.q_wb.conjugate() * g_w).norm(), 1e-14) << s;
    EXPECT_NEAR(r.get<ImuSample>().acc.norm(), NormalGravity(g.lat_deg, g.alt_m), 1e-12) << s;
    // The plumb line leans from w's vertical by the distance over the Earth's radius.
    const Vec3 up_w = (x.q_wb * r.get<ImuSample>().acc).normalized();
    const double lean = std::acos(std::min(1.0, up_w.z()));
    const double d = x.p_wb.head<2>().norm();
    if (d < 1.0) {
      EXPECT_LT(lean, 1e-7);
      ++at_origin;
    } else {
      EXPECT_NEAR(lean, d / 6.37e6, 0.01 * d / 6.37e6) << d;
      ++far;
    }
  }
  EXPECT_GT(at_origin, 700);
  EXPECT_GT(far, 1100);
}

struct KernelRun {
  double max_p = 0.0, max_v = 0.0, max_att = 0.0;  // largest errors against the truth
  std::vector<Vec3> p, v;                          // kernel states at the 100 Hz times (elapsed k/100)
};

// Integrates the rotating simulator's noise-free IMU over FarDrive (600 s, ~9 km) through gins's kernel
// from the true initial state, holding the mean of each pair of samples, with gravity from EarthModel, and
// the Earth rate or (with_earth_rate false) not.
KernelRun IntegrateWithKernel(double imu_rate, bool with_earth_rate) {
  SimOptions options = Rotating(NoiseFreeSim(FarDrive()));
  options.imu_rate = imu_rate;
  options.gnss_rate = options.wheel_rate = 0.0;
  Simulator sim(options);
  const EarthModel earth = EarthModel::Rotating(sim.truth().frame());
  const Vec3 earth_rate_w = with_earth_rate ? earth.rate_w() : Vec3::Zero();
  SimRecord prev, r;
  EXPECT_TRUE(sim.Next(&prev));
  Kinematics k{prev.truth.q_wb, prev.truth.v_w, prev.truth.p_wb};
  KernelRun run;
  run.p.push_back(k.p);
  run.v.push_back(k.v);
  const int keep_every = static_cast<int>(imu_rate / 100.0);
  for (int i = 1; sim.Next(&r); ++i) {
    const ImuSample &a = prev.get<ImuSample>(), &b = r.get<ImuSample>();
    const ImuSample held = HeldBetween(a, b);
    k = ImuStep(k, held.gyro, held.acc, earth.Gravity(k.p), b.t - a.t, nullptr, earth_rate_w);
    const NavState& x = r.truth;  // exact at the sample (record times carry unix-time round-off)
    run.max_p = std::max(run.max_p, (k.p - x.p_wb).norm());
    run.max_v = std::max(run.max_v, (k.v - x.v_w).norm());
    run.max_att = std::max(run.max_att, LogQuat<double>(x.q_wb.conjugate() * k.q).norm());
    if (i % keep_every == 0) {
      run.p.push_back(k.p);
      run.v.push_back(k.v);
    }
    prev = r;
  }
  return run;
}

// The IMU carries the Earth rate, Coriolis and the position-dependent gravity consistently with the truth.
// Through the kernel that models them, the drive is followed within the kernel's own truncation error: at
// 100 Hz 2.2 m, 7.1 mm/s, 1.0 µrad, first order in dt (the specific force is rotated by the attitude at the
// start of each interval), so halving dt halves the error. The Richardson extrapolation 2·x(dt/2) − x(dt)
// cancels that term and lands on the truth: measured 5.6 mm and 0.023 mm/s over 600 s and 9.6 km (limits
// 2 cm, 0.1 mm/s). Without the Earth rate (the flat estimators' model, even with the right gravity) the same
// kernel drifts by 21 km, 104 m/s and 44 mrad: the Earth rate tilts the attitude by 15 deg/h.
TEST(SimEarth, NoiseFreeImuThroughKernelWithEarthRateFollowsTruth) {
  const KernelRun r100 = IntegrateWithKernel(100.0, true);
  const KernelRun r200 = IntegrateWithKernel(200.0, true);
  const KernelRun without = IntegrateWithKernel(100.0, false);
  EXPECT_LT(r100.max_p, 2.5);
  EXPECT_LT(r100.max_v, 0.01);
  EXPECT_LT(r100.max_att, 1.5e-6);
  EXPECT_NEAR(r100.max_p / r200.max_p, 2.0, 0.2);
  EXPECT_NEAR(r100.max_v / r200.max_v, 2.0, 0.2);

  const TruthTrajectory truth(NoiseFreeSim(FarDrive()));
  ASSERT_EQ(r100.p.size(), 60001u);
  ASSERT_EQ(r200.p.size(), 60001u);
  double max_p = 0.0, max_v = 0.0;
  for (size_t i = 0; i < r100.p.size(); ++i) {
    const TruthState x = truth.AtElapsed(static_cast<double>(i) / 100.0);
    max_p = std::max(max_p, (2.0 * r200.p[i] - r100.p[i] - x.p_wb).norm());
    max_v = std::max(max_v, (2.0 * r200.v[i] - r100.v[i] - x.v_w).norm());
  }
  EXPECT_LT(max_p, 0.02);
  EXPECT_LT(max_v, 1e-4);
  EXPECT_GT(without.max_p, 1000.0);
  EXPECT_GT(without.max_att, 0.02);
  RecordProperty("kernel_100hz_max_p_m", test::Sig3(r100.max_p));
  RecordProperty("richardson_max_p_m", test::Sig3(max_p));
  RecordProperty("without_earth_rate_max_p_m", test::Sig3(without.max_p));
}

// truth.csv gives attitude and velocity in the local ENU frame at each row's point (docs/formats.md §4): read back
// through TruthReader (which rotates them into w) they are the simulator's truth in w, to the file's
// rounding, ~9 km from the origin where the local frame is turned 1.5 mrad from w.
TEST(SimEarth, TruthFileReadsBackIntoWorld) {
  SimOptions options = Rotating(FarDrive());
  options.imu_rate = 10.0;
  const std::string dir = test::MakeTempDir("sim_earth");
  Simulate(options, dir);
  const LocalEnuFrame frame(options.origin);
  const std::vector<TruthSample> rows = ReadTruth(dir + "/truth.csv", frame);
  const std::vector<SimRecord> imu = OfType<ImuSample>(RunAll(options));
  ASSERT_EQ(rows.size(), imu.size());
  ASSERT_EQ(rows.size(), 6001u);
  double max_att = 0.0, max_v = 0.0, max_p = 0.0, max_turn = 0.0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const NavState& x = imu[i].truth;
    EXPECT_NEAR(rows[i].t, x.t, 1e-6);
    max_att = std::max(max_att, rows[i].q_wb.angularDistance(x.q_wb));
    max_v = std::max(max_v, (rows[i].v_w - x.v_w).norm());
    max_p = std::max(max_p, (rows[i].p_w - x.p_wb).norm());
    const Mat3 R_w_l = frame.RotationFromLocalEnu(frame.ToGeodetic(x.p_wb));
    max_turn = std::max(max_turn, Eigen::AngleAxisd(R_w_l).angle());
  }
  EXPECT_GT(max_turn, 1.4e-3);  // written unrotated, the attitude would be off by this much
  EXPECT_LT(max_att, 3e-9);     // quaternion components to 1e-9
  EXPECT_LT(max_v, 2e-6);       // to 1e-6 m/s
  EXPECT_LT(max_p, 1e-4);       // lat, lon to 1e-10 deg, alt to 0.1 mm
  RecordProperty("max_attitude_rad", test::Sig3(max_att));
  RecordProperty("max_velocity_m_s", test::Sig3(max_v));
}

// The dual-antenna heading is the baseline's compass heading from true north at the antenna: the azimuth
// of the geodesic from the antenna towards a point 1 m along the baseline. ~9 km from the origin that
// differs from the heading against the origin's north by the meridian convergence, ~0.026°.
TEST(SimEarth, HeadingFromTrueNorthAtTheAntenna) {
  SimOptions options = Rotating(NoiseFreeSim(FarDrive()));
  options.imu_rate = 1.0;
  options.wheel_rate = 0.0;
  const LocalEnuFrame frame(options.origin);
  const GeographicLib::Geodesic& geodesic = GeographicLib::Geodesic::WGS84();
  double max_err = 0.0, max_convergence = 0.0;
  int fixes = 0;
  for (const SimRecord& r : OfType<GnssRecord>(RunAll(options))) {
    const GnssRecord& fix = r.get<GnssRecord>();
    ASSERT_TRUE(fix.heading_valid);
    const NavState& x = r.truth;
    const Vec3 p_ant_w = x.p_wb + x.q_wb * options.lever_b;
    const Vec3 x_G_w = x.q_wb * Vec3(std::cos(options.mount_yaw), std::sin(options.mount_yaw), 0.0);
    const GeodeticPoint a = frame.ToGeodetic(p_ant_w), b = frame.ToGeodetic(p_ant_w + x_G_w);
    double azi1 = 0.0, azi2 = 0.0;
    geodesic.Inverse(a.lat_deg, a.lon_deg, b.lat_deg, b.lon_deg, azi1, azi2);
    max_err = std::max(max_err, std::abs(WrapAngle((fix.heading_deg - azi1) * kDegToRad)));
    const double heading_w = EnuYawToCompassDeg(std::atan2(x_G_w.y(), x_G_w.x()));
    max_convergence = std::max(max_convergence, std::abs(WrapAngle((fix.heading_deg - heading_w) * kDegToRad)));
    ++fixes;
  }
  EXPECT_EQ(fixes, 601);
  EXPECT_LT(max_err, 1e-6);  // rad: a 1 m baseline's height change shifts the geodesic by ~1e-7
  EXPECT_GT(max_convergence, 4e-4);
  RecordProperty("max_heading_error_rad", test::Sig3(max_err));
  RecordProperty("max_convergence_rad", test::Sig3(max_convergence));
}

}  // namespace
}  // namespace gins
