// GNSS velocity (GVEL records) end to end: on a drive with metre-level single-point fixes and no wheels, the
// Doppler velocity makes both estimators' velocity far better, and its records are counted.
#include <gtest/gtest.h>

#include <random>

#include "drive_harness.h"
#include "test_scenarios.h"

namespace gins {
namespace GINS_TEST_FILE {

SimOptions SinglePointDrive(unsigned seed) {
  SimOptions sim = test::TestDrive(seed);
  sim.gnss_sigma_enu = Vec3(1.0, 1.0, 1.5);
  sim.wheel_rate = 0.0;  // no encoders
  sim.gnss_outages.clear();
  return sim;
}

Options SinglePointOptions(const SimOptions& sim) {
  Options o = test::TestRunOptions(sim);
  o.sensors.gnss.min_sigma = 0.3;
  return o;
}

// GVEL records from the truth at each fix: the antenna's velocity with white noise of σ_v.
test::RecordHook WithGvel(double sigma_v, const Vec3& lever_b) {
  auto rng = std::make_shared<std::mt19937>(77);
  auto omega_b = std::make_shared<Vec3>(Vec3::Zero());
  return [=](const SimRecord& rec, const std::function<void(const SimRecord&)>& feed, EstimatorPipeline& session) {
    feed(rec);
    if (rec.is<ImuSample>()) *omega_b = rec.get<ImuSample>().gyro - rec.truth.bg;
    if (!rec.is<GnssRecord>()) return;
    std::normal_distribution<double> n(0.0, sigma_v);
    GnssVelocityRecord g;
    g.t = rec.get<GnssRecord>().t;
    g.v_enu = rec.truth.v_w + rec.truth.q_wb * omega_b->cross(lever_b) + Vec3(n(*rng), n(*rng), n(*rng));
    g.has_sigma = true;
    g.sigma_enu = Vec3::Constant(sigma_v);
    session.AddGnssVelocity(g);
  };
}

TEST(GnssVelocity, ImprovesBothEstimatorsOnSinglePointFixes) {
  const SimOptions sim = SinglePointDrive(4);
  const Options options = SinglePointOptions(sim);
  const test::DriveRun without = test::RunDriveThroughSession(sim, options);
  const test::DriveRun with = test::RunDriveThroughSession(sim, options, WithGvel(0.05, sim.lever_b));
  ASSERT_TRUE(without.initialized && with.initialized);
  const double from = with.init_t + 30.0;
  const test::DriveErrors e0 = test::Errors(without, without.eskf, from), e1 = test::Errors(with, with.eskf, from);
  const test::DriveErrors s0 = test::Errors(without, without.smoother, from);
  const test::DriveErrors s1 = test::Errors(with, with.smoother, from);
  test::PrintErrors("eskf without gvel", e0);
  test::PrintErrors("eskf with gvel", e1);
  test::PrintErrors("smoother without gvel", s0);
  test::PrintErrors("smoother with gvel", s1);
  EXPECT_LT(e1.rmse_vel, 0.5 * e0.rmse_vel);
  EXPECT_LT(s1.rmse_vel, 0.6 * s0.rmse_vel);
  EXPECT_LT(e1.rmse_vel, 0.05);
  EXPECT_LT(s1.rmse_vel, 0.05);
  EXPECT_LT(e1.rmse_h, e0.rmse_h);
  EXPECT_LT(s1.rmse_h, s0.rmse_h);
  // Every record offered after initialisation is used (none rejected on this clean drive).
  const nlohmann::json& ge = with.stats["estimators"]["eskf"]["gnss_velocity"];
  const nlohmann::json& gs = with.stats["estimators"]["smoother"]["gnss_velocity"];
  EXPECT_GT(ge["used"].get<uint64_t>(), 200u);
  EXPECT_EQ(ge["used"], gs["used"]);
  EXPECT_TRUE(ge["rejected"].empty()) << ge.dump();
}

}  // namespace
}  // namespace gins
