// `gins eval` end to end: known answers through files (truth CSV and trajectories written here, in frames
// with different origins), the run → summary → eval round trip with simulated GNSS outages, and usage
// errors. RunCli guards glog's initialisation, so it is called in-process.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "core/geodesy.h"
#include "core/so3.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

namespace fs = std::filesystem;

int Cli(const std::vector<std::string>& args) {
  std::vector<const char*> argv = {"gins"};
  for (const auto& a : args) argv.push_back(a.c_str());
  std::fflush(stdout);
  const int code = RunCli(static_cast<int>(argv.size()), argv.data());
  std::fflush(stdout);
  return code;
}

nlohmann::json Json(const std::string& path) { return nlohmann::json::parse(test::ReadFile(path)); }

// ---- Known answers through files -------------------------------------------------------------------------

constexpr double kT0 = 1700000000.0;
const GeodeticPoint kTruthOrigin{31.5, 120.4, 10.0};

// 0 ... 50 s at 10 Hz, 10 m/s along yaw 0.3 rad, level, starting 2 km east of kTruthOrigin.
struct Point {
  double t;
  GeodeticPoint g;
  Quat q_local;  // attitude in the local ENU at the point
  Vec3 v_local;
};

std::vector<Point> TruthPoints() {
  const LocalEnuFrame frame(kTruthOrigin);
  std::vector<Point> out;
  const Vec3 dir(std::cos(0.3), std::sin(0.3), 0.0);
  for (int k = 0; k <= 500; ++k) {
    const double s = 0.1 * k;
    const Vec3 p = Vec3(2000.0, 0.0, 0.0) + 10.0 * s * dir;
    const GeodeticPoint g = frame.ToGeodetic(p);
    const Mat3 R_l_w = frame.RotationFromLocalEnu(g).transpose();  // directions in the local ENU at the point
    out.push_back({kT0 + s, g, Quat(R_l_w) * QuatFromYaw(0.3), R_l_w * (10.0 * dir)});
  }
  return out;
}

std::string TruthCsv(const std::vector<Point>& pts) {
  std::string text = "t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu\n";
  for (const Point& p : pts) {
    char buf[400];
    std::snprintf(buf, sizeof(buf), "%.6f,%.12f,%.12f,%.6f,%.12f,%.12f,%.12f,%.12f,%.9f,%.9f,%.9f\n", p.t,
                  p.g.lat_deg, p.g.lon_deg, p.g.alt_m, p.q_local.w(), p.q_local.x(), p.q_local.y(), p.q_local.z(),
                  p.v_local.x(), p.v_local.y(), p.v_local.z());
    text += buf;
  }
  return text;
}

// The truth as an estimate in the ENU frame at `origin`, offset by `offset_w` and with a yaw error, at 50 Hz
// (interpolated: the motion is a straight line at constant attitude). `states` writes our states CSV
// (with velocity), else TUM.
std::string Estimate(const GeodeticPoint& origin, const Vec3& offset_w, double yaw_error, bool states) {
  const LocalEnuFrame frame(origin);
  const std::vector<Point> pts = TruthPoints();
  char head[200];
  std::snprintf(head, sizeof(head), "# gins mode=%s frame=ENU origin_lla=%.10f %.10f %.4f\n", states ? "est" : "tum",
                origin.lat_deg, origin.lon_deg, origin.alt_m);
  std::string text = head;
  if (states) text += "t,px,py,pz,vx,vy,vz,qw,qx,qy,qz\n";
  for (size_t i = 0; i + 1 < pts.size(); ++i) {
    for (int j = 0; j < 5; ++j) {
      const double f = j / 5.0;
      const Vec3 a = frame.ToEnu(pts[i].g), b = frame.ToEnu(pts[i + 1].g);
      const Vec3 p = (1.0 - f) * a + f * b + offset_w;
      const Mat3 R_w_l = frame.RotationFromLocalEnu(pts[i].g);
      const Quat q = Quat(R_w_l) * pts[i].q_local * QuatFromYaw(yaw_error);
      const Vec3 v = R_w_l * pts[i].v_local;
      char buf[400];
      if (states) {
        std::snprintf(buf, sizeof(buf), "%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.12f,%.12f,%.12f,%.12f\n",
                      pts[i].t + 0.1 * f, p.x(), p.y(), p.z(), v.x(), v.y(), v.z(), q.w(), q.x(), q.y(), q.z());
      } else {
        std::snprintf(buf, sizeof(buf), "%.6f %.6f %.6f %.6f %.12f %.12f %.12f %.12f\n", pts[i].t + 0.1 * f, p.x(),
                      p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
      }
      text += buf;
    }
  }
  return text;
}

class EvalKnownAnswers : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::MakeTempDir("eval_known");
    truth_ = dir_ + "/truth.csv";
    test::WriteFile(truth_, TruthCsv(TruthPoints()));
    // Estimates in a frame 1 km north of the truth's origin: the eval frame is the first trajectory's.
    const GeodeticPoint other = LocalEnuFrame(kTruthOrigin).ToGeodetic(Vec3(0.0, 1000.0, 5.0));
    offset_ = dir_ + "/offset_states.csv";
    test::WriteFile(offset_, Estimate(other, Vec3(3.0, -4.0, 1.0), 0.0, true));
    yawed_ = dir_ + "/yawed.tum";
    test::WriteFile(yawed_, Estimate(kTruthOrigin, Vec3::Zero(), 2.0 * kDegToRad, false));
    summary_ = dir_ + "/summary.json";
    test::WriteFile(summary_, R"({"input": {"first_time": 1700000000.0},
      "gnss_outages": [[1700000010.0, 1700000020.0], [1700000100.0, 1700000110.0]],
      "gnss_gaps": [[1700000030.0, 1700000035.5]]})");
  }
  std::string dir_, truth_, offset_, yawed_, summary_;
};

TEST_F(EvalKnownAnswers, OffsetsAndRotationsAgainstTruth) {
  const std::string out = dir_ + "/eval.json";
  ASSERT_EQ(Cli({"eval", "--truth", truth_, "--summary", summary_, "--json", out, offset_, yawed_}), 0);
  const nlohmann::json j = Json(out);
  EXPECT_EQ(j["reference"]["kind"], "truth");
  EXPECT_EQ(j["alignment"], "none");
  ASSERT_EQ(j["trajectories"].size(), 2u);
  const auto& a = j["trajectories"][0];
  EXPECT_EQ(a["name"], "est");
  EXPECT_EQ(a["samples"].get<int>(), 500);  // truth 0 ... 49.9 s inside the estimate's span
  EXPECT_NEAR(a["rmse_horizontal_m"].get<double>(), 5.0, 1e-4);
  EXPECT_NEAR(a["rmse_vertical_m"].get<double>(), 1.0, 1e-4);
  EXPECT_NEAR(a["rmse_3d_m"].get<double>(), std::sqrt(26.0), 1e-4);
  EXPECT_NEAR(a["max_horizontal_m"].get<double>(), 5.0, 1e-4);
  EXPECT_NEAR(a["rmse_velocity_m_s"].get<double>(), 0.0, 1e-5);
  EXPECT_NEAR(a["rmse_attitude_deg"].get<double>(), 0.0, 1e-5);
  EXPECT_NEAR(a["rmse_heading_deg"].get<double>(), 0.0, 1e-5);
  EXPECT_NEAR(a["relative_error"]["mean_percent"].get<double>(), 0.0, 1e-4);
  EXPECT_GT(a["relative_error"]["segments"].get<int>(), 0);
  // Outage windows from the summary, merged and sorted: 10-20 s, 30-35.5 s (log gap), 100-110 s (after
  // the end: not scored).
  ASSERT_EQ(j["outage_windows"].size(), 3u);
  EXPECT_EQ(j["outage_windows"][1]["source"], "log gap");
  ASSERT_EQ(a["outages"].size(), 3u);
  EXPECT_NEAR(a["outages"][0]["max_horizontal_m"].get<double>(), 5.0, 1e-4);
  EXPECT_EQ(a["outages"][0]["samples"].get<int>(), 101);
  EXPECT_NEAR(a["outages"][0]["begin_s"].get<double>(), 10.0, 1e-9);
  EXPECT_TRUE(a["outages"][2]["max_horizontal_m"].is_null());
  EXPECT_EQ(a["outages_scored"].get<int>(), 2);
  EXPECT_NEAR(a["outage_drift_rms_m"].get<double>(), 5.0, 1e-4);
  // Outside the windows and 5 s after each: 500 − 151 (10-25 s) − 106 (30-40.5 s) truth times.
  EXPECT_EQ(a["outside_outages_samples"].get<int>(), 243);
  EXPECT_NEAR(a["rmse_horizontal_outside_outages_m"].get<double>(), 5.0, 1e-4);
  EXPECT_EQ(a["outage_settle_s"].get<double>(), 5.0);

  // --outage-settle: 10-22.05 s and 30-37.55 s left out.
  ASSERT_EQ(Cli({"eval", "--truth", truth_, "--summary", summary_, "--outage-settle", "2.05", "--json", out, offset_}),
            0);
  EXPECT_EQ(Json(out)["trajectories"][0]["outside_outages_samples"].get<int>(), 500 - 121 - 76);

  const auto& b = j["trajectories"][1];
  EXPECT_EQ(b["name"], "tum");
  EXPECT_TRUE(b["rmse_velocity_m_s"].is_null());  // a TUM file has no velocity
  EXPECT_NEAR(b["rmse_horizontal_m"].get<double>(), 0.0, 1e-4);
  EXPECT_NEAR(b["rmse_heading_deg"].get<double>(), 2.0, 1e-5);
  EXPECT_NEAR(b["rmse_attitude_deg"].get<double>(), 2.0, 1e-5);
}

TEST_F(EvalKnownAnswers, AlignmentRemovesAKnownOffset) {
  const std::string out = dir_ + "/eval_aligned.json";
  ASSERT_EQ(Cli({"eval", "--truth", truth_, "--align", "yaw", "--json", out, offset_}), 0);
  const nlohmann::json j = Json(out);
  const auto& a = j["trajectories"][0];
  EXPECT_NEAR(a["rmse_3d_m"].get<double>(), 0.0, 1e-4);
  EXPECT_EQ(a["alignment"]["kind"], "yaw");
  EXPECT_NEAR(a["alignment"]["yaw_deg"].get<double>(), 0.0, 1e-4);
}

TEST_F(EvalKnownAnswers, TwoEstimatesAgainstEachOther) {
  const std::string out = dir_ + "/eval_pair.json";
  // The first is the reference; frames differ (1 km apart) and are reconciled.
  ASSERT_EQ(Cli({"eval", "--json", out, yawed_, offset_}), 0);
  const nlohmann::json j = Json(out);
  EXPECT_EQ(j["reference"]["kind"], "trajectory");
  ASSERT_EQ(j["trajectories"].size(), 1u);
  const auto& a = j["trajectories"][0];
  // The offset was written in the other frame, tilted against this one by 1 km / Earth radius.
  EXPECT_NEAR(a["rmse_horizontal_m"].get<double>(), 5.0, 1e-3);
  EXPECT_NEAR(a["rmse_heading_deg"].get<double>(), 2.0, 1e-5);
  EXPECT_TRUE(a["rmse_velocity_m_s"].is_null());  // the reference (TUM) has none
}

TEST_F(EvalKnownAnswers, UsageAndInputErrors) {
  EXPECT_EQ(Cli({"eval", offset_}), 2);                                   // one trajectory, no truth
  EXPECT_EQ(Cli({"eval"}), 2);                                            // nothing
  EXPECT_EQ(Cli({"eval", "--truth", truth_, "--align", "sim3", offset_}), 2);
  EXPECT_EQ(Cli({"eval", "--truth", truth_, dir_ + "/missing.tum"}), 1);  // unreadable input
  EXPECT_EQ(Cli({"eval", "--truth", truth_, summary_}), 1);               // not a trajectory
  // A trajectory entirely outside the truth's time span: nothing to evaluate.
  test::WriteFile(dir_ + "/late.tum", "# gins mode=late frame=ENU origin_lla=31.5 120.4 10\n9e9 0 0 0 0 0 0 1\n");
  EXPECT_EQ(Cli({"eval", "--truth", truth_, dir_ + "/late.tum"}), 1);
}

// ---- Run with simulated outages, then eval on the run directory ----------------------------------------

constexpr const char* kConfig = R"(# eval_cli_test
gnss:
  outages_s: [[0, 1], [20, 8]]
  periodic_outages_s: [30, 3, 5]
simulate:
  seed: 7
  start_time_s: 1700000000
  origin: [31.5, 120.4, 10.0]
  initial_heading_deg: 30
  segments:
    - {duration_s: 10}
    - {duration_s: 8, accel_m_s2: 1.0}
    - {duration_s: 10, yaw_rate_deg_s: 6}
    - {duration_s: 12}
)";

TEST(EvalRoundTrip, RunWithOutagesThenEval) {
  const std::string dir = test::MakeTempDir("eval_roundtrip");
  test::WriteFile(dir + "/config.yaml", kConfig);
  ASSERT_EQ(Cli({"simulate", "--config", dir + "/config.yaml", "--out", dir + "/sim"}), 0);
  const std::string truth = dir + "/sim/truth.csv", run = dir + "/run";
  ASSERT_EQ(Cli({"run", "--config", dir + "/config.yaml", "--log", dir + "/sim/log.txt", "--truth", truth, "--out",
                 run, "--mode", "both"}),
            0);
  const nlohmann::json s = Json(run + "/summary.json");
  // Windows relative to the first record (t0 = 1700000000): [0, 1), [20, 28), then 3 s every 5 s from 30 s
  // while they begin within the 40 s log. 1 Hz fixes at whole seconds: the one at 0 s precedes the end of
  // initialisation and is kept; 8 + 3 + 3 + 1 (the fix at 40 s) are dropped.
  ASSERT_EQ(s["gnss_outages"].size(), 5u);
  EXPECT_EQ(s["gnss_outages"][1][0].get<double>(), kT0 + 20.0);
  EXPECT_EQ(s["gnss_outages"][1][1].get<double>(), kT0 + 28.0);
  EXPECT_EQ(s["gnss_outages"][4][0].get<double>(), kT0 + 40.0);
  EXPECT_EQ(s["gnss_outage_fixes"]["kept_before_initialization"].get<int>(), 1);
  EXPECT_EQ(s["gnss_outage_fixes"]["dropped"].get<int>(), 15);
  EXPECT_TRUE(s["gnss_gaps"].empty());
  // Both estimators saw the same outages: neither used a dropped fix.
  const int fixes = s["input"]["records"]["gnss"].get<int>();
  for (const char* e : {"eskf", "smoother"}) {
    const auto& g = s["estimators"][e]["gnss_position"];
    int rejected = 0;
    for (const auto& [k, v] : g["rejected"].items()) rejected += v.get<int>();
    EXPECT_LE(g["used"].get<int>() + rejected, fixes - 15) << e;
  }
  // The run's comparison: every stream against the truth, the smoother against the ESKF.
  const auto& c = s["comparison"];
  ASSERT_TRUE(c.contains("vs_truth")) << c.dump();
  for (const char* e : {"eskf", "smoother", "smoother_online"}) ASSERT_TRUE(c["vs_truth"].contains(e)) << e;
  EXPECT_TRUE(c.contains("best_horizontal"));
  EXPECT_GT(c["smoother_vs_eskf"]["samples"].get<int>(), 3000);
  EXPECT_EQ(s["truth"], truth);

  // gins eval on the run directory picks up the outputs and the summary.
  const std::string out = dir + "/eval.json";
  ASSERT_EQ(Cli({"eval", "--truth", truth, "--json", out, run}), 0);
  const nlohmann::json j = Json(out);
  ASSERT_EQ(j["trajectories"].size(), 3u);
  EXPECT_EQ(j["trajectories"][0]["name"], "eskf");
  EXPECT_EQ(j["trajectories"][1]["name"], "smoother");
  EXPECT_EQ(j["trajectories"][2]["name"], "smoother_online");
  ASSERT_EQ(j["outage_windows"].size(), 5u);
  for (const auto& t : j["trajectories"]) {
    const std::string name = t["name"];
    SCOPED_TRACE(name);
    // The same numbers as the run's comparison (same files, same code).
    EXPECT_DOUBLE_EQ(t["rmse_horizontal_m"].get<double>(),
                     c["vs_truth"][name]["rmse_horizontal_m"].get<double>());
    EXPECT_DOUBLE_EQ(t["outage_drift_rms_m"].get<double>(), c["vs_truth"][name]["outage_drift_rms_m"].get<double>());
    // And the run's own accuracy section, which is now the same comparison (one evaluator).
    if (name != "smoother_online") {
      EXPECT_NEAR(t["rmse_horizontal_m"].get<double>(), s["accuracy"][name]["rmse_horizontal_m"].get<double>(),
                  1e-4 + 1e-3 * s["accuracy"][name]["rmse_horizontal_m"].get<double>());
    }
    // The first window (before the initialisation, at rest) has the states at rest (the standstill's fixes,
    // docs/estimators.md, "Initialisation"); those at 20, 30 and 35 s the estimates.
    EXPECT_GT(t["outages"][0]["samples"].get<int>(), 0);
    EXPECT_LT(t["outages"][0]["max_horizontal_m"].get<double>(), 0.5);
    EXPECT_GE(t["outages_scored"].get<int>(), 3);
    EXPECT_GT(t["outages"][1]["max_horizontal_m"].get<double>(), 0.0);
    EXPECT_LT(t["outages"][1]["max_horizontal_m"].get<double>(), 5.0);
  }
  EXPECT_TRUE(j["trajectories"][0]["rmse_velocity_m_s"].is_number());   // eskf_states.csv
  EXPECT_TRUE(j["trajectories"][2]["rmse_velocity_m_s"].is_null());     // smoother_online.tum
}

}  // namespace
}  // namespace gins
