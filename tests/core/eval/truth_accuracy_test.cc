// Accuracy against a truth as `gins run` scores an output (summary.json's "accuracy", through
// CompareRunOutputs) and `gins eval` scores a file: the one evaluator of core/eval/trajectory_metrics.h,
// the truth streamed as the reference and the estimate merged in from its own stream. Known answers on
// constructed trajectories, interpolation of the estimate at the truth times, the one gap rule (a
// keyframe-rate output is scored through a GNSS outage), and the truth file reader (plain and gzip,
// malformed rows; core/io/truth_reader.h, tested here beside its main user).
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/eval/run_comparison.h"
#include "core/eval/trajectory_metrics.h"
#include "core/io/log_reader.h"
#include "core/io/trajectory_reader.h"
#include "core/io/truth_reader.h"
#include "core/so3.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kT0 = 1000.0;
constexpr double kTruthDt = 0.125;  // 8 Hz; binary-exact times keep the bracketing unambiguous

// A truth moving with constant velocity and a constant yaw rate (level), so that linear interpolation of
// position and slerp of attitude between estimate samples are exact.
const Vec3 kVel(2.0, 0.5, 0.1);
TruthSample TruthAt(double t) {
  TruthSample s;
  s.t = t;
  s.p_w = Vec3(1.0, -2.0, 3.0) + kVel * (t - kT0);
  s.v_w = kVel;
  s.q_wb = QuatFromYaw(0.3 + 0.05 * (t - kT0));
  return s;
}

std::vector<TruthSample> Truth(double duration) {
  std::vector<TruthSample> out;
  for (int k = 0; k * kTruthDt <= duration + 1e-12; ++k) out.push_back(TruthAt(kT0 + k * kTruthDt));
  return out;
}

TrajectorySample EstimateFromTruth(double t) { return ToTrajectorySample(TruthAt(t)); }

// The estimate scored as `gins run` scores an output with velocities: the truth streamed by as the
// reference, the estimate read alongside from its own source, the gap rule from a first pass over it.
TrajectoryMetrics Score(const std::vector<TruthSample>& truth, const std::vector<TrajectorySample>& estimate,
                        const MetricOptions& options = MetricOptions()) {
  TrajectoryEvaluator ev(VectorSource(estimate), true, EffectiveMaxGap(estimate, options.max_gap), options);
  for (const TruthSample& s : truth) ev.AddReference(ToTrajectorySample(s));
  return ev.Metrics();
}

TEST(AccuracyVsTruth, ConstantEastOffset) {
  const std::vector<TruthSample> truth = Truth(10.0);
  std::vector<TrajectorySample> est;
  for (const TruthSample& s : truth) {
    est.push_back(EstimateFromTruth(s.t));
    est.back().p_w.x() += 1.0;
  }
  const TrajectoryMetrics m = Score(truth, est);
  EXPECT_EQ(m.samples, truth.size());
  EXPECT_NEAR(m.rmse_h, 1.0, 1e-9);
  EXPECT_NEAR(m.max_h, 1.0, 1e-9);
  EXPECT_NEAR(m.rmse_v, 0.0, 1e-9);
  EXPECT_NEAR(m.rmse_3d, 1.0, 1e-9);
  ASSERT_TRUE(m.rmse_vel.has_value());
  EXPECT_NEAR(*m.rmse_vel, 0.0, 1e-9);
  EXPECT_NEAR(m.rmse_heading_deg, 0.0, 1e-6);
  EXPECT_NEAR(m.rmse_att_deg, 0.0, 1e-6);
}

TEST(AccuracyVsTruth, VerticalAndVelocityOffsets) {
  const std::vector<TruthSample> truth = Truth(5.0);
  std::vector<TrajectorySample> est;
  for (const TruthSample& s : truth) {
    est.push_back(EstimateFromTruth(s.t));
    est.back().p_w += Vec3(0.3, -0.4, 0.5);
    est.back().v_w += Vec3(0.0, 0.6, -0.8);
  }
  const TrajectoryMetrics m = Score(truth, est);
  EXPECT_NEAR(m.rmse_h, 0.5, 1e-9);
  EXPECT_NEAR(m.max_h, 0.5, 1e-9);
  EXPECT_NEAR(m.rmse_v, 0.5, 1e-9);
  EXPECT_NEAR(m.rmse_3d, std::sqrt(0.5), 1e-9);
  ASSERT_TRUE(m.rmse_vel.has_value());
  EXPECT_NEAR(*m.rmse_vel, 1.0, 1e-9);
}

TEST(AccuracyVsTruth, ConstantYawOffset) {
  const std::vector<TruthSample> truth = Truth(10.0);
  std::vector<TrajectorySample> est;
  for (const TruthSample& s : truth) {
    est.push_back(EstimateFromTruth(s.t));
    est.back().q_wb = QuatFromYaw(2.0 * kDegToRad) * est.back().q_wb;
  }
  const TrajectoryMetrics m = Score(truth, est);
  EXPECT_EQ(m.samples, truth.size());
  EXPECT_NEAR(m.rmse_heading_deg, 2.0, 1e-6);
  EXPECT_NEAR(m.rmse_att_deg, 2.0, 1e-6);
  EXPECT_NEAR(m.rmse_h, 0.0, 1e-9);
}

TEST(AccuracyVsTruth, HeadingErrorIsWrapped) {
  // Truth yaw near +180°, estimate just across the wrap at −179°: a 2° error, not 358°.
  std::vector<TruthSample> truth(3);
  std::vector<TrajectorySample> est(3);
  for (int k = 0; k < 3; ++k) {
    truth[k].t = est[k].t = kT0 + k;
    truth[k].q_wb = QuatFromYaw(179.0 * kDegToRad);
    est[k].q_wb = QuatFromYaw(-179.0 * kDegToRad);
  }
  EXPECT_NEAR(Score(truth, est).rmse_heading_deg, 2.0, 1e-6);
}

// Estimates at 25 Hz on times between the truth's: the evaluator interpolates them to each truth time.
TEST(AccuracyVsTruth, InterpolatesEstimateAtTruthTimes) {
  const std::vector<TruthSample> truth = Truth(10.0);
  const double first = kT0 + 0.013, dt = 0.04;
  const int n = 245;  // last estimate at kT0 + 9.813
  const double last = first + (n - 1) * dt;
  size_t bracketed = 0;
  for (const TruthSample& s : truth) bracketed += s.t >= first && s.t <= last;

  // Exact estimates: interpolation reproduces the truth (linear motion, constant yaw rate). An error growing
  // linearly in time (east) is interpolated exactly too, so its RMSE is known.
  std::vector<TrajectorySample> exact, growing;
  for (int j = 0; j < n; ++j) {
    const double t = first + j * dt;
    exact.push_back(EstimateFromTruth(t));
    growing.push_back(exact.back());
    growing.back().p_w.x() += 0.1 * (t - kT0);
  }
  double sum = 0.0, max = 0.0;
  for (const TruthSample& s : truth) {
    if (s.t < first || s.t > last) continue;
    const double e = 0.1 * (s.t - kT0);
    sum += e * e;
    max = std::max(max, e);
  }

  const TrajectoryMetrics me = Score(truth, exact);
  EXPECT_EQ(me.samples, bracketed);  // truth before the first / after the last estimate is not evaluated
  EXPECT_EQ(bracketed, 78u);         // kT0 + 0.125 ... kT0 + 9.75
  EXPECT_EQ(me.reference_in_span, bracketed);
  EXPECT_LT(me.rmse_3d, 1e-9);
  EXPECT_LT(*me.rmse_vel, 1e-9);
  EXPECT_LT(me.rmse_heading_deg, 1e-6);
  EXPECT_LT(me.rmse_att_deg, 1e-6);

  const TrajectoryMetrics mg = Score(truth, growing);
  EXPECT_EQ(mg.samples, bracketed);
  EXPECT_NEAR(mg.rmse_h, std::sqrt(sum / bracketed), 1e-9);
  EXPECT_NEAR(mg.max_h, max, 1e-9);
  EXPECT_NEAR(mg.rmse_v, 0.0, 1e-9);
}

// An IMU-rate estimate (16 Hz) is not interpolated across a 2.03 s gap, beyond max(1 s, 3 × its median
// interval): truth inside it is not evaluated (it would otherwise pick up the large error of a straight line
// across the gap).
TEST(AccuracyVsTruth, DoesNotInterpolateAcrossGaps) {
  const std::vector<TruthSample> truth = Truth(10.0);
  std::vector<TrajectorySample> est;
  auto add = [&](double t) {
    est.push_back(EstimateFromTruth(t));
    est.back().p_w.x() += 0.5;
  };
  for (int j = 0; j <= 48; ++j) add(kT0 + j * 0.0625);         // 0 ... 3 s
  add(kT0 + 5.03);                                             // after a 2.03 s gap
  for (int j = 1; j <= 79; ++j) add(kT0 + 5.03 + j * 0.0625);  // ... to 9.9675 s
  const TrajectoryMetrics m = Score(truth, est);
  EXPECT_EQ(m.max_gap, 1.0);
  // Truth at 0 ... 3 s (25 samples) and 5.125 ... 9.875 s (39 samples); 3.125 ... 5 s (16) in the gap.
  EXPECT_EQ(m.samples, 25u + 39u);
  EXPECT_EQ(m.reference_in_span, 25u + 16u + 39u);
  EXPECT_NEAR(m.rmse_h, 0.5, 1e-9);
  EXPECT_NEAR(m.max_h, 0.5, 1e-9);
}

// A keyframe-rate output (smoother_online: 1 Hz, keyframes 1.125 s apart during a 20 s GNSS outage, as on
// the sample drive) is interpolated across up to 3 × its 1 s median interval, so the truth inside the
// outage is scored, drift included. The fixed 1 s of the former run-time evaluator skipped every truth
// time of the outage (the same matcher with a 1 s gap shows it).
TEST(AccuracyVsTruth, KeyframeRateOutputIsScoredThroughA20sOutage) {
  const std::vector<TruthSample> truth = Truth(60.0);
  const double outage_begin = 20.0, outage_end = 40.0;
  std::vector<TrajectorySample> est;
  // Off the truth's 0.125 s grid, so no keyframe coincides with a truth time.
  for (double s = 0.0625; s <= 59.5;) {
    est.push_back(EstimateFromTruth(kT0 + s));
    // Drift east inside the outage, 2 m at its end.
    if (s > outage_begin && s < outage_end + 1.0) est.back().p_w.x() += 0.005 * (s - outage_begin) * (s - outage_begin);
    s += s >= outage_begin && s < outage_end ? 1.125 : 1.0;
  }
  MetricOptions options;
  options.outages = {{kT0 + outage_begin, kT0 + outage_end, "config"}};
  const TrajectoryMetrics m = Score(truth, est, options);
  EXPECT_EQ(m.max_gap, 3.0);
  // Every truth time inside the output's span is scored, the 161 of the outage (20.0 ... 40.0 s) included.
  EXPECT_EQ(m.samples, m.reference_in_span);
  EXPECT_GT(m.samples, 440u);
  ASSERT_EQ(m.outages.size(), 1u);
  EXPECT_EQ(m.outages[0].samples, 161u);
  EXPECT_GT(m.outages[0].max_h, 1.5);
  EXPECT_EQ(m.outages_scored, 1u);

  // The former fixed 1 s: all but the outage's first truth time (20.0 s, before its first long interval)
  // would have been left out, and the drift with them: 160 truth times in the outage and the 2 after it
  // up to the first keyframe back at 1 Hz (40.3125 s).
  size_t in_outage_1s = 0, all_1s = 0;
  for (const MatchedPair& p : MatchAtReferenceTimes(ToTrajectorySamples(truth), est, 1.0)) {
    ++all_1s;
    in_outage_1s += p.ref.t >= kT0 + outage_begin && p.ref.t <= kT0 + outage_end;
  }
  EXPECT_EQ(in_outage_1s, 1u);
  EXPECT_EQ(all_1s + 160u + 2u, m.samples);
}

// Nothing to evaluate (no truth time inside the estimate's span) is an error, not a perfect score; the
// run's summary then says samples 0 with no numbers.
TEST(AccuracyVsTruth, NothingEvaluatedIsNotAPerfectScore) {
  std::vector<TrajectorySample> later;
  for (const TruthSample& s : Truth(1.0)) later.push_back(EstimateFromTruth(s.t + 100.0));
  EXPECT_THROW(Score(Truth(1.0), later), std::invalid_argument);
  const nlohmann::json j = AccuracyToJson(nullptr);
  EXPECT_EQ(j["samples"].get<uint64_t>(), 0u);
  for (const char* key : {"rmse_3d_m", "rmse_horizontal_m", "rmse_vertical_m", "max_horizontal_m",
                          "rmse_velocity_m_s", "rmse_heading_deg", "rmse_attitude_deg"}) {
    EXPECT_TRUE(j.at(key).is_null()) << key;
  }
}

// --- ReadTruth ---

const GeodeticPoint kOrigin{31.5, 120.4, 10.0};

struct Row {
  double t;
  Vec3 p_w;
  Quat q;  // not necessarily normalised in the file
  Vec3 v;
};

std::string TruthCsv(const LocalEnuFrame& frame, const std::vector<Row>& rows) {
  std::string text = "t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu\n# a comment line\n";
  for (const Row& r : rows) {
    const GeodeticPoint g = frame.ToGeodetic(r.p_w);
    char buf[512];
    std::snprintf(buf, sizeof(buf), "%.6f,%.12f,%.12f,%.6f,%.9f,%.9f,%.9f,%.9f,%.6f,%.6f,%.6f\n", r.t, g.lat_deg,
                  g.lon_deg, g.alt_m, r.q.w(), r.q.x(), r.q.y(), r.q.z(), r.v.x(), r.v.y(), r.v.z());
    text += buf;
  }
  return text;
}

std::vector<Row> SampleRows() {
  return {{kT0, Vec3(0.0, 0.0, 0.0), Quat(2.0, 0.0, 0.0, 0.0), Vec3(0.0, 0.0, 0.0)},
          {kT0 + 0.01, Vec3(100.0, -50.0, 2.0), Quat(Eigen::AngleAxisd(0.5, Vec3::UnitZ())), Vec3(1.5, -0.5, 0.1)},
          {kT0 + 0.02, Vec3(-250.5, 1200.25, -3.5), Quat(0.9, 0.1, -0.2, 0.3), Vec3(-3.0, 4.0, 0.0)}};
}

// The file's attitude and velocity are in the local ENU frame at each row's point: ReadTruth rotates them
// into w (by up to 0.01° for the rows 1.2 km from the origin here).
void ExpectMatchesRows(const LocalEnuFrame& frame, const std::vector<TruthSample>& got, const std::vector<Row>& rows) {
  ASSERT_EQ(got.size(), rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    SCOPED_TRACE("row " + std::to_string(i));
    const Mat3 R_w_l = frame.RotationFromLocalEnu(frame.ToGeodetic(rows[i].p_w));
    EXPECT_NEAR(got[i].t, rows[i].t, 1e-9);
    EXPECT_LT((got[i].p_w - rows[i].p_w).norm(), 1e-4);  // 1e-12 deg is 1e-7 m; the height has 1e-6 m
    EXPECT_NEAR(got[i].q_wb.norm(), 1.0, 1e-12);
    EXPECT_LT(got[i].q_wb.angularDistance(Quat(R_w_l) * rows[i].q.normalized()), 1e-8);
    EXPECT_LT((got[i].v_w - R_w_l * rows[i].v).norm(), 1e-9);
  }
  // Far from the origin the rotation is not negligible: the reader did apply it.
  const Mat3 R_far = frame.RotationFromLocalEnu(frame.ToGeodetic(rows.back().p_w));
  EXPECT_GT(LogMat(R_far).norm(), 1e-4);
}

void WriteGzip(const std::string& path, const std::string& text) {
  gzFile f = gzopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(gzwrite(f, text.data(), static_cast<unsigned>(text.size())), static_cast<int>(text.size()));
  ASSERT_EQ(gzclose(f), Z_OK);
}

TEST(ReadTruth, PlainCsvIntoTheWorldFrame) {
  const LocalEnuFrame frame(kOrigin);
  const std::string path = test::MakeTempDir("truth_plain") + "/truth.csv";
  const std::vector<Row> rows = SampleRows();
  test::WriteFile(path, TruthCsv(frame, rows));
  ExpectMatchesRows(frame, ReadTruth(path, frame), rows);
}

TEST(ReadTruth, GzipCsv) {
  const LocalEnuFrame frame(kOrigin);
  const std::string path = test::MakeTempDir("truth_gz") + "/truth.csv.gz";
  const std::vector<Row> rows = SampleRows();
  WriteGzip(path, TruthCsv(frame, rows));
  ASSERT_FALSE(HasFailure());
  // Really compressed (gzip magic), not plain text under a .gz name.
  const std::string raw = test::ReadFile(path);
  ASSERT_GE(raw.size(), 2u);
  EXPECT_EQ(static_cast<unsigned char>(raw[0]), 0x1f);
  EXPECT_EQ(static_cast<unsigned char>(raw[1]), 0x8b);
  ExpectMatchesRows(frame, ReadTruth(path, frame), rows);
}

// The error names the file and the 1-based line of the bad row.
void ExpectInputErrorAt(const std::string& path, const std::string& line_tag) {
  try {
    ReadTruth(path, LocalEnuFrame(kOrigin));
    FAIL() << "expected InputError for " << path;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path + line_tag), std::string::npos) << what;
  }
}

TEST(ReadTruth, MalformedRowNamesFileAndLine) {
  const std::string dir = test::MakeTempDir("truth_bad");
  const std::string good = "1000.0,31.5,120.4,10,1,0,0,0,0,0,0\n";
  const std::string header = "t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu\n";
  // Not a number (line 3).
  test::WriteFile(dir + "/word.csv", header + good + "1000.1,31.5,abc,10,1,0,0,0,0,0,0\n" + good);
  ExpectInputErrorAt(dir + "/word.csv", ":3:");
  // Too few fields (line 2).
  test::WriteFile(dir + "/short.csv", header + "1000.1,31.5,120.4,10,1,0,0\n");
  ExpectInputErrorAt(dir + "/short.csv", ":2:");
  // Not finite (line 4, after a comment).
  test::WriteFile(dir + "/nan.csv", header + good + "# comment\n1000.2,31.5,120.4,nan,1,0,0,0,0,0,0\n");
  ExpectInputErrorAt(dir + "/nan.csv", ":4:");
  // The same in a gzip file.
  WriteGzip(dir + "/word.csv.gz", header + good + "1000.1,31.5,abc,10,1,0,0,0,0,0,0\n");
  ExpectInputErrorAt(dir + "/word.csv.gz", ":3:");
}

// The streaming reader: the same samples as ReadTruth (which collects it), rows not later than the
// previous one dropped; a damaged row deep in the file surfaces when reached, naming file and line.
TEST(TruthReader, StreamsWhatReadTruthReads) {
  const LocalEnuFrame frame(kOrigin);
  const std::string path = test::MakeTempDir("truth_stream") + "/truth.csv.gz";
  std::vector<Row> rows = SampleRows();
  rows.insert(rows.begin() + 2, rows[1]);  // a repeated time: dropped
  WriteGzip(path, TruthCsv(frame, rows));
  ASSERT_FALSE(HasFailure());
  const std::vector<TruthSample> whole = ReadTruth(path, frame);
  ASSERT_EQ(whole.size(), 3u);
  TruthReader reader(path, frame);
  EXPECT_EQ(reader.path(), path);
  TruthSample s;
  for (const TruthSample& w : whole) {
    ASSERT_TRUE(reader.Next(&s));
    EXPECT_EQ(s.t, w.t);
    EXPECT_EQ(s.p_w, w.p_w);
    EXPECT_EQ(s.q_wb.coeffs(), w.q_wb.coeffs());
    EXPECT_EQ(s.v_w, w.v_w);
  }
  EXPECT_FALSE(reader.Next(&s));
  EXPECT_FALSE(reader.Next(&s));
}

TEST(TruthReader, DamagedRowNamesFileAndLineWhenReached) {
  const std::string dir = test::MakeTempDir("truth_stream_bad");
  const std::string header = "t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu\n";
  test::WriteFile(dir + "/late.csv", header + "1000.0,31.5,120.4,10,1,0,0,0,0,0,0\n" +
                                         "1000.1,31.5,120.4,10,1,0,0,0,0,0,0\n" +
                                         "1000.2,31.5,120.4,10,1,0,0,0,0,0,0,7\n");
  TruthReader reader(dir + "/late.csv", LocalEnuFrame(kOrigin));
  TruthSample s;
  ASSERT_TRUE(reader.Next(&s));
  ASSERT_TRUE(reader.Next(&s));
  try {
    reader.Next(&s);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/late.csv:4: truth row has more than 11 fields"), std::string::npos)
        << e.what();
  }
  // Rows that would put NaN into the frame: a latitude beyond the pole, a zero quaternion.
  for (const auto& [row, why] : {std::pair<std::string, std::string>{"1000.1,91.5,120.4,10,1,0,0,0,0,0,0\n",
                                                                     "latitude, longitude or height out of range"},
                                 {"1000.1,31.5,120.4,10,0,0,0,0,0,0,0\n", "quaternion is not a rotation"}}) {
    test::WriteFile(dir + "/bad.csv", header + "1000.0,31.5,120.4,10,1,0,0,0,0,0,0\n" + row);
    TruthReader bad(dir + "/bad.csv", LocalEnuFrame(kOrigin));
    ASSERT_TRUE(bad.Next(&s));
    try {
      bad.Next(&s);
      ADD_FAILURE() << "accepted " << row;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(dir + "/bad.csv:3: truth row's " + why), std::string::npos) << e.what();
    }
  }
  test::WriteFile(dir + "/header_only.csv", header);
  TruthReader empty(dir + "/header_only.csv", LocalEnuFrame(kOrigin));
  EXPECT_THROW(empty.Next(&s), InputError);  // no truth rows
  EXPECT_THROW(TruthReader(dir + "/none.csv", LocalEnuFrame(kOrigin)), InputError);
}

// The truth pulled from a reader as the reference (as the run does) gives what the truth held in memory
// gives.
TEST(AccuracyVsTruth, TruthPulledFromAReader) {
  const LocalEnuFrame frame(kOrigin);
  const std::string path = test::MakeTempDir("truth_pull") + "/truth.csv";
  std::vector<Row> rows;
  for (int k = 0; k <= 80; ++k) {
    const TruthSample s = TruthAt(kT0 + k * kTruthDt);
    rows.push_back({s.t, s.p_w, s.q_wb, s.v_w});
  }
  test::WriteFile(path, TruthCsv(frame, rows));
  std::vector<TrajectorySample> est;
  for (int k = 0; k <= 250; ++k) {
    est.push_back(EstimateFromTruth(kT0 - 0.5 + 0.04 * k));
    est.back().p_w.x() += 0.01 * k;
  }
  const MetricOptions options;
  TruthReader reader(path, frame);
  TrajectoryEvaluator pulled(VectorSource(est), true, EffectiveMaxGap(est, options.max_gap), options);
  TruthSample s;
  while (reader.Next(&s)) pulled.AddReference(ToTrajectorySample(s));
  const TrajectoryMetrics a = pulled.Metrics(), b = Score(ReadTruth(path, frame), est);
  EXPECT_GT(a.samples, 70u);
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.rmse_3d, b.rmse_3d);
  EXPECT_EQ(a.max_h, b.max_h);
  EXPECT_EQ(a.rmse_vel, b.rmse_vel);
  EXPECT_EQ(a.rmse_att_deg, b.rmse_att_deg);
}

TEST(ReadTruth, MissingOrEmptyFileThrows) {
  const std::string dir = test::MakeTempDir("truth_missing");
  EXPECT_THROW(ReadTruth(dir + "/none.csv", LocalEnuFrame(kOrigin)), InputError);
  test::WriteFile(dir + "/header_only.csv", "t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu\n");
  EXPECT_THROW(ReadTruth(dir + "/header_only.csv", LocalEnuFrame(kOrigin)), InputError);
}

}  // namespace
}  // namespace gins
