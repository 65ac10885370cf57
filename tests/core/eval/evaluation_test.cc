// Accuracy evaluation against a truth: known answers on constructed trajectories, interpolation of the
// estimate at the truth times, and the truth file reader (plain and gzip, malformed rows).
#include "core/eval/evaluation.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/io/log_reader.h"
#include "core/so3.h"
#include "test_util.h"

namespace gins {
namespace {

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

NavState EstimateFromTruth(double t) {
  const TruthSample s = TruthAt(t);
  NavState x;
  x.t = t;
  x.p_wb = s.p_w;
  x.v_w = s.v_w;
  x.q_wb = s.q_wb;
  return x;
}

TEST(StreamingEvaluator, ConstantEastOffset) {
  const std::vector<TruthSample> truth = Truth(10.0);
  StreamingEvaluator ev(truth);
  for (const TruthSample& s : truth) {
    NavState x = EstimateFromTruth(s.t);
    x.p_wb.x() += 1.0;
    ev.Add(x);
  }
  const AccuracyMetrics m = ev.Metrics();
  EXPECT_EQ(m.count, truth.size());
  EXPECT_NEAR(m.rmse_h, 1.0, 1e-9);
  EXPECT_NEAR(m.max_h, 1.0, 1e-9);
  EXPECT_NEAR(m.rmse_v, 0.0, 1e-9);
  EXPECT_NEAR(m.rmse_3d, 1.0, 1e-9);
  EXPECT_NEAR(m.rmse_vel, 0.0, 1e-9);
  EXPECT_NEAR(m.rmse_heading_deg, 0.0, 1e-6);
  EXPECT_NEAR(m.rmse_att_deg, 0.0, 1e-6);
}

TEST(StreamingEvaluator, VerticalAndVelocityOffsets) {
  const std::vector<TruthSample> truth = Truth(5.0);
  StreamingEvaluator ev(truth);
  for (const TruthSample& s : truth) {
    NavState x = EstimateFromTruth(s.t);
    x.p_wb += Vec3(0.3, -0.4, 0.5);
    x.v_w += Vec3(0.0, 0.6, -0.8);
    ev.Add(x);
  }
  const AccuracyMetrics m = ev.Metrics();
  EXPECT_NEAR(m.rmse_h, 0.5, 1e-9);
  EXPECT_NEAR(m.max_h, 0.5, 1e-9);
  EXPECT_NEAR(m.rmse_v, 0.5, 1e-9);
  EXPECT_NEAR(m.rmse_3d, std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(m.rmse_vel, 1.0, 1e-9);
}

TEST(StreamingEvaluator, ConstantYawOffset) {
  const std::vector<TruthSample> truth = Truth(10.0);
  StreamingEvaluator ev(truth);
  for (const TruthSample& s : truth) {
    NavState x = EstimateFromTruth(s.t);
    x.q_wb = QuatFromYaw(2.0 * kDegToRad) * x.q_wb;
    ev.Add(x);
  }
  const AccuracyMetrics m = ev.Metrics();
  EXPECT_EQ(m.count, truth.size());
  EXPECT_NEAR(m.rmse_heading_deg, 2.0, 1e-6);
  EXPECT_NEAR(m.rmse_att_deg, 2.0, 1e-6);
  EXPECT_NEAR(m.rmse_h, 0.0, 1e-9);
}

TEST(StreamingEvaluator, HeadingErrorIsWrapped) {
  // Truth yaw near +180°, estimate just across the wrap at −179°: a 2° error, not 358°.
  std::vector<TruthSample> truth(3);
  for (int k = 0; k < 3; ++k) {
    truth[k].t = kT0 + k;
    truth[k].q_wb = QuatFromYaw(179.0 * kDegToRad);
  }
  StreamingEvaluator ev(truth);
  for (int k = 0; k < 3; ++k) {
    NavState x;
    x.t = kT0 + k;
    x.q_wb = QuatFromYaw(-179.0 * kDegToRad);
    ev.Add(x);
  }
  EXPECT_NEAR(ev.Metrics().rmse_heading_deg, 2.0, 1e-6);
}

// Estimates at 25 Hz on times between the truth's: the evaluator interpolates them to each truth time.
TEST(StreamingEvaluator, InterpolatesEstimateAtTruthTimes) {
  const std::vector<TruthSample> truth = Truth(10.0);
  const double first = kT0 + 0.013, dt = 0.04;
  const int n = 245;  // last estimate at kT0 + 9.813
  const double last = first + (n - 1) * dt;
  size_t bracketed = 0;
  for (const TruthSample& s : truth) bracketed += s.t >= first && s.t <= last;

  // Exact estimates: interpolation reproduces the truth (linear motion, constant yaw rate).
  StreamingEvaluator exact(truth);
  // An error growing linearly in time (east): interpolated exactly too, so the RMSE is known.
  StreamingEvaluator growing(truth);
  for (int j = 0; j < n; ++j) {
    const double t = first + j * dt;
    const NavState x = EstimateFromTruth(t);
    exact.Add(x);
    NavState y = x;
    y.p_wb.x() += 0.1 * (t - kT0);
    growing.Add(y);
  }
  double sum = 0.0, max = 0.0;
  for (const TruthSample& s : truth) {
    if (s.t < first || s.t > last) continue;
    const double e = 0.1 * (s.t - kT0);
    sum += e * e;
    max = std::max(max, e);
  }

  const AccuracyMetrics me = exact.Metrics();
  EXPECT_EQ(me.count, bracketed);  // truth before the first / after the last estimate is not evaluated
  EXPECT_EQ(bracketed, 78u);       // kT0 + 0.125 ... kT0 + 9.75
  EXPECT_LT(me.rmse_3d, 1e-9);
  EXPECT_LT(me.rmse_vel, 1e-9);
  EXPECT_LT(me.rmse_heading_deg, 1e-6);
  EXPECT_LT(me.rmse_att_deg, 1e-6);

  const AccuracyMetrics mg = growing.Metrics();
  EXPECT_EQ(mg.count, bracketed);
  EXPECT_NEAR(mg.rmse_h, std::sqrt(sum / bracketed), 1e-9);
  EXPECT_NEAR(mg.max_h, max, 1e-9);
  EXPECT_NEAR(mg.rmse_v, 0.0, 1e-9);
}

// No interpolation across a gap in the estimate longer than 1 s: truth inside it is not evaluated (it would
// otherwise pick up the large error of a straight line across the gap).
TEST(StreamingEvaluator, DoesNotInterpolateAcrossGaps) {
  const std::vector<TruthSample> truth = Truth(10.0);
  StreamingEvaluator ev(truth);
  auto add = [&](double t, double east_error) {
    NavState x = EstimateFromTruth(t);
    x.p_wb.x() += east_error;
    ev.Add(x);
  };
  for (int j = 0; j <= 48; ++j) add(kT0 + j * 0.0625, 0.5);         // 0 ... 3 s
  add(kT0 + 5.03, 0.5);                                             // after a 2.03 s gap
  for (int j = 1; j <= 79; ++j) add(kT0 + 5.03 + j * 0.0625, 0.5);  // ... to 9.9675 s
  const AccuracyMetrics m = ev.Metrics();
  // Truth at 0 ... 3 s (25 samples) and 5.125 ... 9.875 s (39 samples).
  EXPECT_EQ(m.count, 25u + 39u);
  EXPECT_NEAR(m.rmse_h, 0.5, 1e-9);
  EXPECT_NEAR(m.max_h, 0.5, 1e-9);
}

TEST(StreamingEvaluator, NoEstimatesGiveZeroCount) {
  StreamingEvaluator ev(Truth(1.0));
  EXPECT_EQ(ev.Metrics().count, 0u);
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
  test::WriteFile(dir + "/header_only.csv", header);
  TruthReader empty(dir + "/header_only.csv", LocalEnuFrame(kOrigin));
  EXPECT_THROW(empty.Next(&s), InputError);  // no truth rows
  EXPECT_THROW(TruthReader(dir + "/none.csv", LocalEnuFrame(kOrigin)), InputError);
}

// The evaluator pulling its truth from a reader gives what it gives over the same truth in memory.
TEST(StreamingEvaluator, PullsTruthFromAReader) {
  const LocalEnuFrame frame(kOrigin);
  const std::string path = test::MakeTempDir("truth_pull") + "/truth.csv";
  std::vector<Row> rows;
  for (int k = 0; k <= 80; ++k) {
    const TruthSample s = TruthAt(kT0 + k * kTruthDt);
    rows.push_back({s.t, s.p_w, s.q_wb, s.v_w});
  }
  test::WriteFile(path, TruthCsv(frame, rows));
  TruthReader reader(path, frame);
  StreamingEvaluator pulled([&reader](TruthSample* s) { return reader.Next(s); });
  StreamingEvaluator held(ReadTruth(path, frame));
  for (int k = 0; k <= 250; ++k) {
    NavState x = EstimateFromTruth(kT0 - 0.5 + 0.04 * k);
    x.p_wb.x() += 0.01 * k;
    pulled.Add(x);
    held.Add(x);
  }
  const AccuracyMetrics a = pulled.Metrics(), b = held.Metrics();
  EXPECT_GT(a.count, 70u);
  EXPECT_EQ(a.count, b.count);
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
