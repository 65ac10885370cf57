// Reading trajectories back (core/trajectory_reader.h): what TumWriter and StatesCsvWriter write reads back,
// foreign TUM files, gzip, malformed files (whole and streamed), and re-expressing a trajectory in another
// ENU frame.
#include "core/io/trajectory_reader.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <string>

#include "core/io/log_reader.h"
#include "core/so3.h"
#include "core/io/trajectory_writer.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

const GeodeticPoint kOrigin{31.5, 120.4, 10.0};

std::vector<NavState> States() {
  std::vector<NavState> out;
  for (int k = 0; k < 5; ++k) {
    NavState x;
    x.t = 1700000000.0 + 0.01 * k;
    x.p_wb = Vec3(1.5 * k, -2.0 + k, 0.25 * k);
    x.v_w = Vec3(150.0, 100.0, 25.0);
    x.q_wb = QuatFromYaw(0.1 * k) * Quat(Eigen::AngleAxisd(0.02, Vec3::UnitX()));
    out.push_back(x);
  }
  return out;
}

TEST(ReadTrajectory, ReadsWhatTheWritersWrite) {
  const std::string dir = test::MakeTempDir("traj_reader");
  {
    TumWriter tum(dir + "/eskf.tum", "eskf", kOrigin);
    StatesCsvWriter csv(dir + "/eskf_states.csv");
    for (const NavState& x : States()) {
      tum.Add(x);
      csv.Add(x, Vec3::Constant(0.1), Vec3::Constant(0.2), Vec3::Constant(0.3), 1.0);
    }
    tum.Commit();
    csv.Commit();
  }
  for (const char* file : {"/eskf.tum", "/eskf_states.csv"}) {
    SCOPED_TRACE(file);
    const Trajectory t = ReadTrajectory(dir + file);
    EXPECT_EQ(t.mode, "eskf");
    ASSERT_TRUE(t.origin.has_value());
    EXPECT_NEAR(t.origin->lat_deg, kOrigin.lat_deg, 1e-10);
    EXPECT_NEAR(t.origin->lon_deg, kOrigin.lon_deg, 1e-10);
    EXPECT_NEAR(t.origin->alt_m, kOrigin.alt_m, 1e-4);
    const auto states = States();
    ASSERT_EQ(t.samples.size(), states.size());
    for (size_t i = 0; i < states.size(); ++i) {
      EXPECT_NEAR(t.samples[i].t, states[i].t, 1e-6);
      EXPECT_LT((t.samples[i].p_w - states[i].p_wb).norm(), 1e-5);
      EXPECT_LT(t.samples[i].q_wb.angularDistance(states[i].q_wb), 1e-8);
    }
    const bool csv = std::string(file).find(".csv") != std::string::npos;
    EXPECT_EQ(t.has_velocity, csv);
    EXPECT_EQ(t.has_sigma, csv);
    if (csv) {
      EXPECT_LT((t.samples[2].v_w - states[2].v_w).norm(), 1e-5);
      EXPECT_NEAR(t.samples[2].sigma_p.y(), 0.1, 1e-9);
    }
    for (const TrajectorySample& s : t.samples) EXPECT_TRUE(s.yaw_known);
  }
}

// A state CSV starts with its column names: its origin is the TUM file's beside it; alone it has none (and
// is read as a foreign trajectory, in the evaluation's frame).
TEST(ReadTrajectory, AStatesCsvTakesItsOriginFromItsTumFile) {
  const std::string dir = test::MakeTempDir("traj_reader_sibling");
  {
    StatesCsvWriter csv(dir + "/batch_states.csv");
    for (const NavState& x : States()) csv.Add(x, Vec3::Constant(0.1), Vec3::Constant(0.2), Vec3::Constant(0.3), 1.0);
    csv.Commit();
  }
  EXPECT_FALSE(ReadTrajectory(dir + "/batch_states.csv").origin.has_value());
  {
    TumWriter tum(dir + "/batch.tum", "batch", kOrigin);
    tum.Add(States()[0]);
    tum.Commit();
  }
  const Trajectory t = ReadTrajectory(dir + "/batch_states.csv");
  ASSERT_TRUE(t.origin.has_value());
  EXPECT_NEAR(t.origin->lat_deg, kOrigin.lat_deg, 1e-10);
  EXPECT_EQ(t.mode, "batch");
}

// A state CSV's yaw σ of an unknown angle (a state at rest before the initialisation) reads as no yaw.
TEST(ReadTrajectory, AnUnknownYawSigmaReadsAsNoYaw) {
  const std::string dir = test::MakeTempDir("traj_reader_yaw");
  {
    StatesCsvWriter csv(dir + "/eskf_states.csv");
    const auto states = States();
    csv.Add(states[0], Vec3::Constant(0.1), Vec3::Constant(0.2), Vec3(0.01, 0.01, kUnknownYawSigma), 1.0);
    csv.Add(states[1], Vec3::Constant(0.1), Vec3::Constant(0.2), Vec3(0.01, 0.01, 0.2), 1.0);
    csv.Commit();
  }
  const Trajectory t = ReadTrajectory(dir + "/eskf_states.csv");
  ASSERT_EQ(t.samples.size(), 2u);
  EXPECT_FALSE(t.samples[0].yaw_known);
  EXPECT_TRUE(t.samples[1].yaw_known);
}

void WriteGzip(const std::string& path, const std::string& text) {
  gzFile f = gzopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  gzwrite(f, text.data(), static_cast<unsigned>(text.size()));
  gzclose(f);
}

TEST(ReadTrajectory, ForeignTumGzipAndRepeatedTimes) {
  const std::string dir = test::MakeTempDir("traj_foreign");
  // evo-style TUM: no origin; a repeated time stamp (the later row wins); CRLF; a blank line.
  const std::string text =
      "# timestamp tx ty tz qx qy qz qw\r\n"
      "1.0 0 0 0 0 0 0 1\r\n"
      "\n"
      "2.0 1 0 0 0 0 0 1\r\n"
      "2.0 5 0 0 0 0 0 1\r\n"
      "3.0 2 0 0 0 0 0.7071068 0.7071068\r\n";
  WriteGzip(dir + "/foreign.tum.gz", text);
  const Trajectory t = ReadTrajectory(dir + "/foreign.tum.gz");
  EXPECT_FALSE(t.origin.has_value());
  EXPECT_TRUE(t.mode.empty());
  EXPECT_FALSE(t.has_velocity);
  ASSERT_EQ(t.samples.size(), 3u);
  EXPECT_EQ(t.samples[1].p_w.x(), 5.0);
  EXPECT_NEAR(YawOfXAxis<double>(t.samples[2].q_wb.toRotationMatrix()), kPi / 2.0, 1e-6);
  EXPECT_NEAR(t.samples[2].q_wb.norm(), 1.0, 1e-12);
}

void ExpectInputError(const std::string& path, const std::string& text, const std::string& what) {
  test::WriteFile(path, text);
  try {
    ReadTrajectory(path);
    FAIL() << "no error for " << path;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST(ReadTrajectory, MalformedFilesNameFileAndLine) {
  const std::string d = test::MakeTempDir("traj_bad");
  ExpectInputError(d + "/a.tum", "1 0 0 0 0 0 0 1\n2 0 x 0 0 0 0 1\n", d + "/a.tum:2: field 3 is not a finite number");
  ExpectInputError(d + "/b.tum", "1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n", d + "/b.tum:2: expected 8 fields, got 7");
  ExpectInputError(d + "/c.tum", "2 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n", d + "/c.tum:2: time goes backwards");
  ExpectInputError(d + "/d.tum", "# only a comment\n", d + "/d.tum: no trajectory rows");
  ExpectInputError(d + "/e.tum", "1 0 0 0 0 0 0 nan\n", d + "/e.tum:1: field 8 is not a finite number");
  ExpectInputError(d + "/f.tum", "1 0 0 0 0 0 0 0\n", "quaternion is not a rotation");
  ExpectInputError(d + "/g.csv", "t,x,y\n1,2,3\n", d + "/g.csv:1: header lacks column 'px'");
  EXPECT_THROW(ReadTrajectory(d + "/missing.tum"), InputError);
}

// The streaming reader hands out what ReadTrajectory collects, with the header known from the start.
TEST(TrajectoryReader, StreamsWhatReadTrajectoryReads) {
  const std::string dir = test::MakeTempDir("traj_stream");
  {
    StatesCsvWriter csv(dir + "/eskf_states.csv");
    for (const NavState& x : States()) csv.Add(x, Vec3::Constant(0.1), Vec3::Constant(0.2), Vec3::Constant(0.3), 1.0);
    csv.Commit();
  }
  WriteGzip(dir + "/foreign.tum.gz", "# t x y z qx qy qz qw\n1 0 0 0 0 0 0 1\n2 1 0 0 0 0 0 1\n2 5 0 0 0 0 0 1\n");
  for (const char* file : {"/eskf_states.csv", "/foreign.tum.gz"}) {
    SCOPED_TRACE(file);
    const Trajectory whole = ReadTrajectory(dir + file);
    TrajectoryReader reader(dir + file);
    EXPECT_EQ(reader.path(), dir + file);
    EXPECT_EQ(reader.mode(), whole.mode);
    EXPECT_EQ(reader.origin().has_value(), whole.origin.has_value());
    EXPECT_EQ(reader.has_velocity(), whole.has_velocity);
    TrajectorySample s;
    size_t n = 0;
    while (reader.Next(&s)) {
      ASSERT_LT(n, whole.samples.size());
      EXPECT_EQ(s.t, whole.samples[n].t);
      EXPECT_EQ(s.p_w, whole.samples[n].p_w);  // the repeated time: the later row
      EXPECT_EQ(s.v_w, whole.samples[n].v_w);
      EXPECT_EQ(s.q_wb.coeffs(), whole.samples[n].q_wb.coeffs());
      ++n;
    }
    EXPECT_EQ(n, whole.samples.size());
    EXPECT_FALSE(reader.Next(&s));  // stays at the end
  }
}

// A damaged row deep in a file: the rows before it stream out, then the error names file and line.
TEST(TrajectoryReader, ErrorsNameFileAndLineWhenReached) {
  const std::string d = test::MakeTempDir("traj_stream_bad");
  auto rows_then_throw = [](const std::string& path, const std::string& text, size_t good, const std::string& what) {
    test::WriteFile(path, text);
    TrajectoryReader reader(path);
    TrajectorySample s;
    for (size_t i = 0; i < good; ++i) ASSERT_TRUE(reader.Next(&s)) << i;
    try {
      reader.Next(&s);
      FAIL() << "no error for " << path;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  const std::string rows = "1 0 0 0 0 0 0 1\n# a comment\n2 0 0 0 0 0 0 1\n3 0 0 0 0 0 0 1\n";
  // The row before the damaged one is handed out once the damaged one is read: two of the three.
  rows_then_throw(d + "/a.tum", rows + "4 0 x 0 0 0 0 1\n", 2, d + "/a.tum:5: field 3 is not a finite number");
  rows_then_throw(d + "/b.tum", rows + "2.5 0 0 0 0 0 0 1\n", 2, d + "/b.tum:5: time goes backwards");
  rows_then_throw(d + "/c.tum", rows + ",, ,\n", 2, d + "/c.tum:5: expected 8 fields, got 0");
  rows_then_throw(d + "/d.csv", "t,px,py,pz,qw,qx,qy,qz\n1,0,0,0,1,0,0,0\n2,0,0,0,1,0,0,0\nt,px\n", 1,
                  d + "/d.csv:4: expected a row of numbers, got 't'");
  // The first row, an empty or a missing file: already the constructor.
  auto construct_throws = [](const std::string& path, const std::string& what) {
    try {
      TrajectoryReader reader(path);
      FAIL() << "no error for " << path;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  test::WriteFile(d + "/e.tum", "# header\n1 0 0 0 0 0 0 nan\n");
  construct_throws(d + "/e.tum", d + "/e.tum:2: field 8 is not a finite number");
  test::WriteFile(d + "/f.tum", "# only a comment\n");
  construct_throws(d + "/f.tum", d + "/f.tum: no trajectory rows");
  construct_throws(d + "/missing.tum", d + "/missing.tum: cannot open trajectory file");
}

// Two ENU frames 3 km apart: the same geodetic points, expressed in either, map onto each other exactly.
TEST(ChangeFrame, IsExactBetweenDistantOrigins) {
  const LocalEnuFrame a(kOrigin);
  const GeodeticPoint far = a.ToGeodetic(Vec3(2000.0, -2200.0, 15.0));
  const LocalEnuFrame b(far);
  Trajectory t;
  t.origin = kOrigin;
  for (int k = 0; k < 4; ++k) {
    TrajectorySample s;
    s.t = k;
    s.p_w = Vec3(100.0 * k, -50.0 * k, 3.0);
    s.q_wb = QuatFromYaw(0.3 * k);
    s.v_w = Vec3(1.0, 2.0, 0.0);
    t.samples.push_back(s);
  }
  const Trajectory original = t;
  ChangeFrame(a, b, &t);
  ASSERT_TRUE(t.origin.has_value());
  EXPECT_EQ(t.origin->lat_deg, far.lat_deg);
  const Mat3 R_b_a = b.RotationFromLocalEnu(kOrigin);
  for (size_t i = 0; i < t.samples.size(); ++i) {
    // Position: through the geodesy.
    EXPECT_LT((t.samples[i].p_w - b.ToEnu(a.ToGeodetic(original.samples[i].p_w))).norm(), 1e-6);
    // Directions: rotated by the frames' relative rotation (0.02° here).
    EXPECT_LT((t.samples[i].v_w - R_b_a * original.samples[i].v_w).norm(), 1e-12);
    EXPECT_LT(t.samples[i].q_wb.angularDistance(Quat(R_b_a) * original.samples[i].q_wb), 1e-12);
  }
  EXPECT_GT(LogMat(R_b_a).norm(), 3e-4);
}

TEST(ToTrajectorySamples, CopiesTruth) {
  std::vector<TruthSample> truth(2);
  truth[1].t = 1.0;
  truth[1].p_w = Vec3(1, 2, 3);
  truth[1].v_w = Vec3(4, 5, 6);
  const auto s = ToTrajectorySamples(truth);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[1].p_w, truth[1].p_w);
  EXPECT_EQ(s[1].v_w, truth[1].v_w);
  EXPECT_EQ(s[1].t, 1.0);
}

}  // namespace
}  // namespace gins
