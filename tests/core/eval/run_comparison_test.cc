// The comparison at the end of a run (core/eval/run_comparison.h), which streams every file: on a run
// directory written by the trajectory writers, it gives exactly what the whole-trajectory evaluation (as
// `gins eval` does it) gives on the same files, and the run's "accuracy" is its scores against the truth;
// it reads nothing it does not compare; damaged files name file and line.
#include "core/eval/run_comparison.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/io/log_reader.h"
#include "core/so3.h"
#include "core/io/trajectory_reader.h"
#include "core/io/trajectory_writer.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

const GeodeticPoint kOrigin{31.5, 120.4, 10.0};
constexpr double kT0 = 1700000000.0;

// A drive over 300 s with a 40 s standstill at 100 s.
NavState TruthAt(double s) {
  NavState x;
  x.t = kT0 + s;
  const double moving = s < 100.0 ? s : std::max(100.0, s - 40.0);
  const double yaw = 0.3 + moving / 80.0;
  x.p_wb = Vec3(150.0 * std::sin(moving / 80.0), 150.0 * (1.0 - std::cos(moving / 80.0)), 2.0);
  x.q_wb = QuatFromYaw(yaw);
  const bool standing = s >= 100.0 && s < 140.0;
  x.v_w = standing ? Vec3::Zero() : Vec3(1.875 * std::cos(moving / 80.0), 1.875 * std::sin(moving / 80.0), 0.0);
  return x;
}

// An estimate off the truth by a slow drift, larger inside [200, 230) s.
NavState EstimateAt(double s, double scale) {
  NavState x = TruthAt(s);
  const double outage = s >= 200.0 && s < 230.0 ? 0.002 * (s - 200.0) * (s - 200.0) : 0.0;
  x.p_wb += scale * Vec3(0.05 * std::sin(s / 7.0) + outage, 0.03 * std::cos(s / 5.0), 0.02 * std::sin(s / 3.0));
  x.v_w += scale * Vec3(0.01 * std::cos(s / 7.0), 0.0, 0.0);
  x.q_wb = (x.q_wb * Quat(Eigen::AngleAxisd(scale * 0.002 * std::sin(s / 4.0), Vec3::UnitX()))).normalized();
  return x;
}

// A run directory: eskf and smoother at 100 Hz (with a 5 s hole in the ESKF), smoother_online at 1 Hz, and
// a truth file at 50 Hz starting before the estimates.
struct RunDir {
  std::string dir, truth;
};

RunDir WriteRunDirectory(const std::string& name) {
  RunDir run;
  run.dir = test::MakeTempDir(name);
  const Vec3 sigma = Vec3::Constant(0.1);
  {
    TumWriter eskf_tum(run.dir + "/eskf.tum", "eskf", kOrigin);
    StatesCsvWriter eskf(run.dir + "/eskf_states.csv");
    TumWriter smoother_tum(run.dir + "/smoother.tum", "smoother", kOrigin);
    StatesCsvWriter smoother(run.dir + "/smoother_states.csv");
    TumWriter online(run.dir + "/smoother_online.tum", "smoother_online", kOrigin);
    for (int k = 200; k <= 29800; ++k) {
      const double s = 0.01 * k;
      if (s < 60.0 || s > 65.0) {
        const NavState e = EstimateAt(s, 1.0);
        eskf_tum.Add(e);
        eskf.Add(e, sigma, sigma, sigma, 1.0);
      }
      const NavState m = EstimateAt(s, 0.3);
      smoother_tum.Add(m);
      smoother.Add(m, sigma, sigma, sigma, 1.0);
      if (k % 100 == 0) online.Add(EstimateAt(s, 0.6));
    }
    eskf_tum.Commit();
    eskf.Commit();
    smoother_tum.Commit();
    smoother.Commit();
    online.Commit();
  }
  const LocalEnuFrame frame(kOrigin);
  std::string text = "t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu\n";
  for (int k = 0; k <= 15000; ++k) {
    const NavState x = TruthAt(0.02 * k);
    const GeodeticPoint g = frame.ToGeodetic(x.p_wb);
    // Attitude and velocity in the local ENU frame at the point, as ReadTruth expects.
    const Mat3 R_l_w = frame.RotationFromLocalEnu(g).transpose();
    const Quat q_lb = (Quat(R_l_w) * x.q_wb).normalized();
    const Vec3 v_l = R_l_w * x.v_w;
    char buf[512];
    std::snprintf(buf, sizeof(buf), "%.6f,%.10f,%.10f,%.4f,%.9f,%.9f,%.9f,%.9f,%.6f,%.6f,%.6f\n", x.t, g.lat_deg,
                  g.lon_deg, g.alt_m, q_lb.w(), q_lb.x(), q_lb.y(), q_lb.z(), v_l.x(), v_l.y(), v_l.z());
    text += buf;
  }
  run.truth = run.dir + "/truth.csv";
  test::WriteFile(run.truth, text);
  return run;
}

const std::vector<TimeWindow> kOutages = {{kT0 + 20.0, kT0 + 30.0, "config"},
                                          {kT0 + 58.0, kT0 + 70.0, "log gap"},
                                          {kT0 + 110.0, kT0 + 130.0, "config"},
                                          {kT0 + 200.0, kT0 + 230.0, "config"}};

TEST(CompareRunOutputs, StreamedEqualsWholeTrajectoryEvaluation) {
  const RunDir run = WriteRunDirectory("run_comparison");
  const std::vector<std::string> names = {"eskf", "smoother", "smoother_online"};
  const TruthFile truth{run.truth, LocalEnuFrame(kOrigin)};
  const nlohmann::json c = CompareRunOutputs(run.dir, names, &truth, kOutages, kT0);

  MetricOptions options;
  options.outages = kOutages;
  const std::vector<TrajectorySample> reference = ToTrajectorySamples(ReadTruth(run.truth, truth.frame));
  const Trajectory eskf = ReadTrajectory(StreamFile(run.dir, "eskf"));
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    const Trajectory t = ReadTrajectory(StreamFile(run.dir, name));
    const TrajectoryMetrics m = EvaluateTrajectory(reference, true, t.samples, t.has_velocity, options);
    EXPECT_EQ(c["vs_truth"][name], MetricsToJson(m, kT0)) << c["vs_truth"][name].dump();
    if (name == "eskf") continue;
    const TrajectoryMetrics d = EvaluateTrajectory(eskf.samples, true, t.samples, t.has_velocity, options);
    const nlohmann::json& j = c[name + "_vs_eskf"];
    EXPECT_EQ(j["samples"].get<uint64_t>(), d.samples);
    EXPECT_EQ(j["rms_horizontal_difference_m"].get<double>(), d.rmse_h);
    EXPECT_EQ(j["max_horizontal_difference_m"].get<double>(), d.max_h);
    EXPECT_EQ(j["rms_vertical_difference_m"].get<double>(), d.rmse_v);
    EXPECT_EQ(j["rms_heading_difference_deg"].get<double>(), d.rmse_heading_deg);
    EXPECT_EQ(j["rms_attitude_difference_deg"].get<double>(), d.rmse_att_deg);
    EXPECT_EQ(j["largest_horizontal_difference_in_outages_m"].get<double>(), d.outage_max);
    EXPECT_EQ(j.contains("rms_velocity_difference_m_s"), d.rmse_vel.has_value());
  }
  // What the scenario exercises: the keyframe-rate output at 3 × its 1 s median, segments across the
  // standstill, the ESKF's hole, outages scored.
  EXPECT_EQ(c["vs_truth"]["smoother_online"]["max_gap_s"].get<double>(), 3.0);
  EXPECT_GT(c["vs_truth"]["smoother"]["relative_error"]["segments"].get<int>(), 10000);
  EXPECT_LT(c["vs_truth"]["eskf"]["samples"].get<int>(), c["vs_truth"]["eskf"]["reference_samples_in_span"].get<int>());
  EXPECT_EQ(c["vs_truth"]["eskf"]["outages_scored"].get<int>(), 4);
  EXPECT_EQ(c["best_horizontal"], "smoother");
}

// `gins run`'s "accuracy" is this comparison: the metrics handed back are those of "vs_truth", and the
// short form carries the same numbers under the same keys. A keyframe-rate output whose keyframes are
// 1.1 s apart through the drift window [200, 230] s is scored all through it (3 × its 1 s median), where
// a fixed 1 s left it out.
TEST(CompareRunOutputs, AccuracyIsTheComparisonAgainstTheTruth) {
  const RunDir run = WriteRunDirectory("run_comparison_accuracy");
  {
    TumWriter online(run.dir + "/smoother_online.tum", "smoother_online", kOrigin);
    // Off the truth's 0.02 s grid, so no keyframe coincides with a truth time.
    for (double s = 2.01; s <= 298.0; s += s >= 200.0 && s < 230.0 ? 1.1 : 1.0) online.Add(EstimateAt(s, 0.6));
    online.Commit();
  }
  const std::vector<std::string> names = {"eskf", "smoother", "smoother_online"};
  const TruthFile truth{run.truth, LocalEnuFrame(kOrigin)};
  std::map<std::string, TrajectoryMetrics> accuracy;
  const nlohmann::json c = CompareRunOutputs(run.dir, names, &truth, kOutages, kT0, &accuracy);
  ASSERT_EQ(accuracy.size(), names.size());
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    EXPECT_EQ(MetricsToJson(accuracy.at(name), kT0), c["vs_truth"][name]);
    const nlohmann::json a = AccuracyToJson(&accuracy.at(name));
    EXPECT_EQ(a.size(), 9u);
    for (const auto& [key, value] : a.items()) EXPECT_EQ(value, c["vs_truth"][name][key]) << key;
  }
  const TrajectoryMetrics& online = accuracy.at("smoother_online");
  EXPECT_NEAR(online.max_gap, 3.0, 1e-5);
  EXPECT_EQ(online.samples, online.reference_in_span);
  ASSERT_EQ(online.outages.size(), kOutages.size());
  EXPECT_EQ(online.outages[3].samples, 1501u);  // 50 Hz over [200, 230] s
  EXPECT_GT(online.outages[3].max_h, 0.5);      // the drift there (0.6 × 1.8 m at its end) counts
  // The former fixed 1 s: at most the window's first truth time.
  const Trajectory file = ReadTrajectory(StreamFile(run.dir, "smoother_online"));
  size_t in_window_1s = 0;
  for (const MatchedPair& p :
       MatchAtReferenceTimes(ToTrajectorySamples(ReadTruth(run.truth, truth.frame)), file.samples, 1.0)) {
    in_window_1s += p.ref.t >= kT0 + 200.0 && p.ref.t <= kT0 + 230.0;
  }
  EXPECT_LE(in_window_1s, 1u);
}

// Only the smoother's outputs and no truth: nothing to compare (comparisons are against the truth or the
// ESKF), and nothing is read.
TEST(CompareRunOutputs, NothingToCompareWithoutTruthOrEskf) {
  const RunDir run = WriteRunDirectory("run_comparison_none");
  test::WriteFile(run.dir + "/smoother_online.tum", "not a trajectory\n");  // would fail if read
  EXPECT_TRUE(CompareRunOutputs(run.dir, {"smoother", "smoother_online"}, nullptr, kOutages, kT0).is_null());
}

TEST(CompareRunOutputs, DamagedOutputNamesFileAndLine) {
  const RunDir run = WriteRunDirectory("run_comparison_bad");
  std::string text = test::ReadFile(run.dir + "/smoother_online.tum");
  text += "1700000299.5 1 2 x 0 0 0 1\n";  // after the 2 + 297 rows: line 299
  test::WriteFile(run.dir + "/smoother_online.tum", text);
  try {
    CompareRunOutputs(run.dir, {"eskf", "smoother_online"}, nullptr, kOutages, kT0);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(run.dir + "/smoother_online.tum:299: field 4 is not a finite number"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace gins
