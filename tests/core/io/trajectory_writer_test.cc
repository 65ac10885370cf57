// Output files: complete or absent (AtomicFile), and the TUM / state CSV formats read back.
#include "core/io/trajectory_writer.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

namespace fs = std::filesystem;

std::vector<std::string> DirEntries(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

std::vector<double> Numbers(const std::string& row, char sep) {
  std::vector<double> v;
  std::istringstream in(row);
  std::string field;
  while (std::getline(in, field, sep)) v.push_back(std::stod(field));
  return v;
}

NavState SampleState() {
  NavState x;
  x.t = 1700000123.456789;
  x.p_wb = Vec3(12.34567, -7.65432, 1.23456);
  x.v_w = Vec3(3.5, -1.25, 0.125);
  x.q_wb = Quat(Eigen::AngleAxisd(0.7, Vec3(0.2, -0.3, 0.9).normalized()));
  x.bg = Vec3(1e-4, -2e-4, 3e-4);
  x.ba = Vec3(0.01, -0.02, 0.03);
  return x;
}

const GeodeticPoint kOrigin{31.508183, 120.401989, 12.5};

TEST(AtomicFile, UncommittedLeavesNothing) {
  const std::string dir = test::MakeTempDir("atomic_uncommitted");
  const std::string path = dir + "/out.txt";
  {
    AtomicFile f(path);
    f.Write("partial contents\n");
    // While open, the data goes to a temporary name, never to the final path.
    EXPECT_FALSE(fs::exists(path));
    EXPECT_EQ(DirEntries(dir).size(), 1u);
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(DirEntries(dir).empty());  // no temporary file left either
}

TEST(AtomicFile, CommittedFileHasTheContents) {
  const std::string dir = test::MakeTempDir("atomic_committed");
  const std::string path = dir + "/out.txt";
  {
    AtomicFile f(path);
    f.Write("line one\n");
    std::fprintf(f.stream(), "line %d\n", 2);
    f.Commit();
    EXPECT_EQ(f.path(), path);
    f.Commit();  // a second commit is harmless
  }
  ASSERT_TRUE(fs::exists(path));
  EXPECT_EQ(test::ReadFile(path), "line one\nline 2\n");
  EXPECT_EQ(DirEntries(dir), std::vector<std::string>{"out.txt"});
}

// What an interrupted process leaves (apps/interrupt.h): the committed file, not the uncommitted one's
// temporary; a CommitGroup being committed is waited for. In a child: AbandonUncommittedFiles keeps its lock.
TEST(AtomicFile, AbandonRemovesOnlyTheUncommittedAndWaitsForACommitGroup) {
  const std::string dir = test::MakeTempDir("atomic_abandon");
  std::fflush(stdout);
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    AtomicFile done(dir + "/done.txt");
    done.Write("done\n");
    done.Commit();
    auto* left = new AtomicFile(dir + "/left.txt");  // never destroyed: the process ends as on a signal
    left->Write("half");
    std::fflush(left->stream());
    // A group committing on another thread: the abandon waits until both of its files are in place.
    std::atomic<bool> holding{false};
    std::thread group([&] {
      const CommitGroup commit;
      holding = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      for (const char* name : {"/a.txt", "/b.txt"}) {
        AtomicFile f(dir + name);
        f.Write(name);
        f.Commit();
      }
    });
    while (!holding) std::this_thread::yield();
    const size_t removed = AbandonUncommittedFiles();
    const bool left_gone = !fs::exists(left->path()) && DirEntries(dir).size() == 3;
    group.detach();  // done, or (had the abandon not waited) blocked for good on the list's lock
    _exit(removed == 1 && left_gone ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  std::vector<std::string> names = DirEntries(dir);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"a.txt", "b.txt", "done.txt"}));
  EXPECT_EQ(test::ReadFile(dir + "/b.txt"), "/b.txt");
}

// Contents larger than the stream's own buffer (256 KiB) arrive whole and in order.
TEST(AtomicFile, LargeContentsArriveWhole) {
  const std::string dir = test::MakeTempDir("atomic_large");
  const std::string path = dir + "/out.txt";
  std::string expected;
  {
    AtomicFile f(path);
    for (int i = 0; i < 200000; ++i) {
      char line[32];
      const int n = std::snprintf(line, sizeof(line), "%d,%d\n", i, i * 7);
      expected.append(line, static_cast<size_t>(n));
      std::fputs(line, f.stream());
    }
    f.Commit();
  }
  ASSERT_GT(expected.size(), 2u << 20);
  EXPECT_EQ(test::ReadFile(path), expected);
}

TEST(AtomicFile, CommitReplacesAnExistingFile) {
  const std::string dir = test::MakeTempDir("atomic_replace");
  const std::string path = dir + "/out.txt";
  test::WriteFile(path, "old\n");
  {
    AtomicFile f(path);
    f.Write("new\n");
    EXPECT_EQ(test::ReadFile(path), "old\n");  // untouched until the commit
  }
  EXPECT_EQ(test::ReadFile(path), "old\n");  // an abandoned write leaves the old file
  {
    AtomicFile f(path);
    f.Write("new\n");
    f.Commit();
  }
  EXPECT_EQ(test::ReadFile(path), "new\n");
  EXPECT_EQ(DirEntries(dir).size(), 1u);
}

TEST(AtomicFile, UncreatableFileThrows) {
  const std::string dir = test::MakeTempDir("atomic_missing_dir");
  try {
    AtomicFile f(dir + "/no/such/dir/out.txt");
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("out.txt"), std::string::npos) << e.what();
  }
}

TEST(TrajectoryHeader, NamesModeFrameAndOrigin) {
  EXPECT_EQ(TrajectoryHeader("smoother", kOrigin),
            "# gins mode=smoother frame=ENU origin_lla=31.5081830000 120.4019890000 12.5000\n");
}

TEST(TumWriter, HeaderAndRowRoundTrip) {
  const std::string dir = test::MakeTempDir("tum");
  const std::string path = dir + "/eskf.tum";
  const NavState x = SampleState();
  {
    TumWriter w(path, "eskf", kOrigin);
    w.Add(x);
    EXPECT_EQ(w.count(), 1u);
    w.Commit();
  }
  const std::vector<std::string> lines = Lines(test::ReadFile(path));
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0] + "\n", TrajectoryHeader("eskf", kOrigin));
  const std::vector<double> v = Numbers(lines[1], ' ');
  ASSERT_EQ(v.size(), 8u);  // t x y z qx qy qz qw
  EXPECT_NEAR(v[0], x.t, 1e-6);
  EXPECT_NEAR(v[1], x.p_wb.x(), 1e-5);
  EXPECT_NEAR(v[2], x.p_wb.y(), 1e-5);
  EXPECT_NEAR(v[3], x.p_wb.z(), 1e-5);
  EXPECT_NEAR(v[4], x.q_wb.x(), 1e-9);
  EXPECT_NEAR(v[5], x.q_wb.y(), 1e-9);
  EXPECT_NEAR(v[6], x.q_wb.z(), 1e-9);
  EXPECT_NEAR(v[7], x.q_wb.w(), 1e-9);
}

TEST(TumWriter, UncommittedLeavesNothing) {
  const std::string dir = test::MakeTempDir("tum_uncommitted");
  {
    TumWriter w(dir + "/eskf.tum", "eskf", kOrigin);
    w.Add(SampleState());
  }
  EXPECT_TRUE(DirEntries(dir).empty());
}

// The column names are the first line (pandas.read_csv opens it as it is); the origin is the TUM file's.
TEST(StatesCsvWriter, ColumnNamesFirstThenRows) {
  const std::string dir = test::MakeTempDir("states_csv");
  const std::string path = dir + "/smoother_states.csv";
  const NavState x = SampleState();
  const Vec3 sp(0.011, 0.012, 0.013), sv(0.0021, 0.0022, 0.0023), sa(1.5e-4, 2.5e-4, 3.5e-3);
  const double scale = 0.990123;
  {
    StatesCsvWriter w(path);
    w.Add(x, sp, sv, sa, scale);
    w.Commit();
  }
  const std::vector<std::string> lines = Lines(test::ReadFile(path));
  ASSERT_EQ(lines.size(), 2u);
  const std::vector<std::string> expected_columns = {
      "t",        "px",       "py",          "pz",          "vx",          "vy",        "vz",
      "qw",       "qx",       "qy",          "qz",          "bgx",         "bgy",       "bgz",
      "bax",      "bay",      "baz",         "sigma_px",    "sigma_py",    "sigma_pz",  "sigma_vx",
      "sigma_vy", "sigma_vz", "sigma_att_e", "sigma_att_n", "sigma_att_u", "odom_scale"};
  std::vector<std::string> columns;
  {
    std::istringstream in(lines[0]);
    std::string c;
    while (std::getline(in, c, ',')) columns.push_back(c);
  }
  EXPECT_EQ(columns, expected_columns);

  const std::vector<double> v = Numbers(lines[1], ',');
  ASSERT_EQ(v.size(), expected_columns.size());
  EXPECT_NEAR(v[0], x.t, 1e-6);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(v[1 + i], x.p_wb[i], 1e-5);
    EXPECT_NEAR(v[4 + i], x.v_w[i], 1e-5);
    // Biases and σ with 5 significant digits.
    EXPECT_NEAR(v[11 + i], x.bg[i], 1e-4 * std::abs(x.bg[i]));
    EXPECT_NEAR(v[14 + i], x.ba[i], 1e-4 * std::abs(x.ba[i]));
    EXPECT_NEAR(v[17 + i], sp[i], 1e-4 * sp[i]);
    EXPECT_NEAR(v[20 + i], sv[i], 1e-4 * sv[i]);
    EXPECT_NEAR(v[23 + i], sa[i], 1e-4 * sa[i]);
  }
  EXPECT_NEAR(v[7], x.q_wb.w(), 1e-9);
  EXPECT_NEAR(v[8], x.q_wb.x(), 1e-9);
  EXPECT_NEAR(v[9], x.q_wb.y(), 1e-9);
  EXPECT_NEAR(v[10], x.q_wb.z(), 1e-9);
  EXPECT_NEAR(v[26], scale, 1e-6);
}

// No NaN or infinity ever reaches a file: a state with one is refused whole (and the caller told), every
// other one written. A finite value of any size gets its complete line (the widest: 27 fields of 1e300).
TEST(StatesCsvWriter, RefusesNonFiniteStatesAndWritesHugeOnesWhole) {
  const std::string dir = test::MakeTempDir("states_csv_non_finite");
  const std::string csv = dir + "/eskf_states.csv", tum = dir + "/eskf.tum";
  const NavState x = SampleState();
  const Vec3 s(0.1, 0.1, 0.1);
  const double nan = std::nan(""), inf = HUGE_VAL;
  NavState huge = x;
  huge.t += 1.0;
  huge.p_wb = Vec3::Constant(-1e300);
  huge.v_w = Vec3::Constant(1e300);
  {
    StatesCsvWriter w(csv);
    TumWriter t(tum, "eskf", kOrigin);
    NavState bad = x;
    bad.v_w.y() = nan;
    EXPECT_FALSE(w.Add(bad, s, s, s, 1.0));
    EXPECT_FALSE(t.Add(bad));
    EXPECT_FALSE(w.Add(x, s, Vec3(0.1, inf, 0.1), s, 1.0));
    EXPECT_FALSE(w.Add(x, s, s, Vec3(nan, 0.1, 0.1), 1.0));
    EXPECT_FALSE(w.Add(x, s, s, s, nan));
    EXPECT_TRUE(w.Add(x, s, s, s, 1.0));
    EXPECT_TRUE(w.Add(huge, Vec3::Constant(1e300), Vec3::Constant(1e300), s, 1e300));
    EXPECT_TRUE(t.Add(x));
    EXPECT_TRUE(t.Add(huge));
    EXPECT_EQ(t.count(), 2u);
    w.Commit();
    t.Commit();
  }
  for (const auto& [path, sep, columns] : {std::tuple{csv, ',', 27u}, std::tuple{tum, ' ', 8u}}) {
    const std::vector<std::string> lines = Lines(test::ReadFile(path));
    ASSERT_EQ(lines.size(), 3u) << path;  // the columns or the comment, then two rows
    for (size_t i = lines.size() - 2; i < lines.size(); ++i) {
      EXPECT_EQ(lines[i].find("nan"), std::string::npos) << lines[i];
      EXPECT_EQ(lines[i].find("inf"), std::string::npos) << lines[i];
      const std::vector<double> v = Numbers(lines[i], sep);
      ASSERT_EQ(v.size(), columns) << path;
      for (double d : v) EXPECT_TRUE(std::isfinite(d));
    }
    EXPECT_DOUBLE_EQ(Numbers(lines.back(), sep)[1], -1e300);
  }
}

// TumWriter::AddWithStates writes the bytes Add, StatesCsvWriter::Add and GeodeticCsvWriter::Add write, huge
// values included; a state with a non-finite σ still gets its TUM line (the TUM has no σ) but no CSV line
// (a non-finite velocity σ: no states line, a geodetic one), as with the separate calls.
TEST(TumWriter, AddWithStatesWritesWhatTheSeparateWritersWrite) {
  const std::string dir = test::MakeTempDir("tum_with_states");
  NavState huge = SampleState();
  huge.t += 1.0;
  huge.p_wb = Vec3(-1e300, 2.5e17, -0.0);
  huge.q_wb = Quat(0.5, -0.5, 0.5, -0.5);
  NavState later = SampleState();
  later.t += 2.0;
  later.p_wb = Vec3(-3.25, 1234.5, 7.0);
  const Vec3 s(0.1, 2e-7, 3e4);
  const Vec3 nan_sigma(0.1, std::nan(""), 0.1);
  const LocalEnuFrame frame(kOrigin);
  struct Row {
    NavState x;
    Vec3 sigma_p, sigma_v;
  };
  const Row rows[] = {{SampleState(), s, s}, {huge, s, s}, {SampleState(), nan_sigma, s}, {later, s, nan_sigma}};
  for (const char* variant : {"pair", "one"}) {
    const std::string base = dir + "/" + variant;
    TumWriter t(base + ".tum", "eskf", kOrigin);
    StatesCsvWriter w(base + "_states.csv");
    GeodeticCsvWriter g(base + "_lla.csv", frame);
    for (const Row& r : rows) {
      if (std::string(variant) == "pair") {
        t.Add(r.x);
        w.Add(r.x, r.sigma_p, r.sigma_v, s, 0.99);
        g.Add(r.x, r.sigma_p);
      } else {
        EXPECT_TRUE(t.AddWithStates(&w, &g, r.x, r.sigma_p, r.sigma_v, s, 0.99));
      }
    }
    EXPECT_EQ(t.count(), 4u);
    t.Commit();
    w.Commit();
    g.Commit();
  }
  for (const char* file : {".tum", "_states.csv", "_lla.csv"}) {
    EXPECT_EQ(test::ReadFile(dir + "/one" + file), test::ReadFile(dir + "/pair" + file)) << file;
  }
  EXPECT_EQ(Lines(test::ReadFile(dir + "/one_states.csv")).size(), 3u);  // columns, two rows
  // Columns and all but the third state (no position σ); the huge one far off the Earth, but finite.
  EXPECT_EQ(Lines(test::ReadFile(dir + "/one_lla.csv")).size(), 4u);
}

// The geodetic track: column names first, then latitude, longitude and height of the state's position in
// the frame (to 0.1 mm back through the frame) with its σ; a non-finite state is refused.
TEST(GeodeticCsvWriter, WritesTheStatesOnTheEarthWithTheirSigma) {
  const std::string dir = test::MakeTempDir("lla_csv");
  const std::string path = dir + "/eskf_lla.csv";
  const LocalEnuFrame frame(kOrigin);
  NavState x = SampleState();
  x.p_wb = Vec3(1234.5678, -876.54321, 15.25);
  const Vec3 sp(0.011, 0.012, 0.031);
  {
    GeodeticCsvWriter w(path, frame);
    EXPECT_TRUE(w.Add(x, sp));
    NavState bad = x;
    bad.p_wb.x() = std::nan("");
    EXPECT_FALSE(w.Add(bad, sp));
    EXPECT_FALSE(w.Add(x, Vec3(0.1, HUGE_VAL, 0.1)));
    w.Commit();
  }
  const std::vector<std::string> lines = Lines(test::ReadFile(path));
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0] + "\n", kGeodeticCsvColumns);
  EXPECT_EQ(lines[0], "t,lat_deg,lon_deg,height_m,sigma_e_m,sigma_n_m,sigma_u_m");
  const std::vector<double> v = Numbers(lines[1], ',');
  ASSERT_EQ(v.size(), 7u);
  EXPECT_NEAR(v[0], x.t, 1e-6);
  const Vec3 back = frame.ToEnu(GeodeticPoint{v[1], v[2], v[3]});
  EXPECT_LT((back - x.p_wb).norm(), 1e-4);
  EXPECT_NEAR(v[1], 31.5081830000 - 876.54321 / 110900.0, 1e-3);  // about 111 km per degree of latitude
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(v[4 + i], sp[i], 1e-4 * sp[i]);
}

}  // namespace
}  // namespace gins
