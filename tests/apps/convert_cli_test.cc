// `gins convert` end to end: usage, a refused file (exit 1, the line named, no output), and a simulated
// drive written as i2Nav files, converted, and run through `gins run --mode eskf` against its truth.
//
// RunCli runs in a forked child (as in cli_test.cc, whose runner is private to that file): glog allows one
// InitGoogleLogging per process, and a child keeps one call's global state from the next.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "apps/cli.h"
#include "core/io/log_reader.h"
#include "test_util.h"

namespace gins {
namespace {

namespace fs = std::filesystem;

struct CliResult {
  int code = -1;  // exit code, -1 if the child did not exit normally
  std::string out, err;
};

CliResult RunCliInChild(const std::vector<std::string>& args, const std::string& dir) {
  std::vector<const char*> argv = {"gins"};
  for (const auto& a : args) argv.push_back(a.c_str());
  const std::string out_path = dir + "/stdout.txt", err_path = dir + "/stderr.txt";
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = fork();
  if (pid < 0) return {};
  if (pid == 0) {
    std::FILE* out = std::fopen(out_path.c_str(), "w");
    std::FILE* err = std::fopen(err_path.c_str(), "w");
    if (out == nullptr || err == nullptr || dup2(fileno(out), 1) < 0 || dup2(fileno(err), 2) < 0) _exit(97);
    int code = 99;
    try {
      code = RunCli(static_cast<int>(argv.size()), argv.data());
    } catch (...) {
      code = 98;  // RunCli must not throw
    }
    std::fflush(stdout);
    std::fflush(stderr);
    _exit(code);
  }
  int status = 0;
  CliResult r;
  if (waitpid(pid, &status, 0) != pid) return r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = test::ReadFile(out_path);
  r.err = test::ReadFile(err_path);
  return r;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

std::string Fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, v);
  return buf;
}

std::string Sci(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

// A drive like cli_test's (10 s standstill, accelerating, a left turn, a cruise), at 200 Hz like i2Nav's
// IMUs, in GPS seconds of week; its wheel records are dropped (i2Nav files have none). Converted logs carry no heading:
// the run takes its yaw from the motion.
constexpr const char* kConfig = R"(# convert_cli_test: the conversion round trip, on the flat Earth (tests/solver cover the Earth model)
simulate:
  earth_rotation: false
  seed: 7
  start_time_s: 357000
  origin: [30.46, 114.47, 23.0]
  initial_heading_deg: 30
  segments:
    - {duration_s: 10}
    - {duration_s: 8, accel_m_s2: 1.0}
    - {duration_s: 10, yaw_rate_deg_s: 6}
    - {duration_s: 12}
  imu_rate_hz: 200
  gnss_rate_hz: 1
init:
  wait_for_heading: false
  sigma_yaw_deg: 180
gravity:
  earth_rotation: false
)";

// Writes a gins log's IMU and GNSS records as i2Nav files: increments over (t_prev, t] by the trapezoid
// rule (the first sample's over one period of its own rate), FRD axes; GNSS σ as north, east, up.
void WriteI2nav(const std::string& log, const std::string& imu_path, const std::string& gnss_path, size_t* n_imu) {
  LogReader reader(log, InputOptions{});
  std::string imu, gnss;
  LogRecord r;
  bool have_prev = false;
  ImuSample prev;
  *n_imu = 0;
  while (reader.Next(&r)) {
    if (r.type == LogRecord::Type::kGnss) {
      const GnssRecord& g = r.gnss;
      gnss += Fixed(g.t, 3) + " " + Fixed(g.lat_deg, 11) + " " + Fixed(g.lon_deg, 11) + " " + Fixed(g.alt_m, 4) + " " +
              Sci(g.sigma_enu.y()) + " " + Sci(g.sigma_enu.x()) + " " + Sci(g.sigma_enu.z()) + "\n";
    }
    if (r.type != LogRecord::Type::kImu) continue;
    const ImuSample& s = r.imu;
    const double dt = have_prev ? s.t - prev.t : 0.005;
    const Vec3 w = have_prev ? 0.5 * (prev.gyro + s.gyro) : s.gyro;
    const Vec3 f = have_prev ? 0.5 * (prev.acc + s.acc) : s.acc;
    const Vec3 dtheta_frd = Vec3(w.x(), -w.y(), -w.z()) * dt, dv_frd = Vec3(f.x(), -f.y(), -f.z()) * dt;
    imu += Fixed(s.t, 6);
    for (int i = 0; i < 3; ++i) imu += " " + Sci(dtheta_frd[i]);
    for (int i = 0; i < 3; ++i) imu += " " + Sci(dv_frd[i]);
    imu += "\n";
    prev = s;
    have_prev = true;
    ++*n_imu;
  }
  test::WriteFile(imu_path, imu);
  test::WriteFile(gnss_path, gnss);
}

// The converted log with the drive's wheel records merged in (ties: converted first). gins finds its
// initial heading from a dual-antenna heading or, from the motion, against the wheels' dead reckoning: a
// log with neither (an i2Nav conversion) does not initialise yet ("waiting for the vehicle to move").
std::string WithWheels(const std::string& converted, const std::string& sim_log) {
  std::vector<std::pair<double, std::string>> odom;
  for (const auto& line : Lines(test::ReadFile(sim_log))) {
    if (line.rfind("ODOM ", 0) == 0) odom.emplace_back(std::stod(line.substr(5)), line);
  }
  std::string merged;
  size_t i = 0;
  for (const auto& line : Lines(test::ReadFile(converted))) {
    const size_t space = line.find(' ');
    const double t = line[0] == '#' ? 0.0 : std::stod(line.substr(space + 1));
    for (; i < odom.size() && odom[i].first < t; ++i) merged += odom[i].second + "\n";
    merged += line + "\n";
  }
  for (; i < odom.size(); ++i) merged += odom[i].second + "\n";
  return merged;
}

TEST(ConvertCli, HelpAndUsageErrors) {
  const std::string dir = test::MakeTempDir("convert_cli");
  const CliResult help = RunCliInChild({"convert", "--help"}, dir);
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("--imu-data"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("t dθx dθy dθz dvx dvy dvz"), std::string::npos) << help.out;
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"convert", "--imu", "a", "--gnss", "b", "--out", "c"},                           // no --format
           {"convert", "--format", "kitti", "--imu", "a", "--gnss", "b", "--out", "c"},      // unknown format
           {"convert", "--format", "i2nav", "--imu", "a", "--gnss", "b"},                    // no --out
           {"convert", "--format", "i2nav", "--imu", "a", "--gnss", "b", "--out", "c", "--imu-data", "deg"},
       }) {
    EXPECT_EQ(RunCliInChild(args, dir).code, 2) << args[1] << " " << args[2];
  }
}

TEST(ConvertCli, RefusedInputExitsOneNamingTheLineAndWritesNothing) {
  const std::string dir = test::MakeTempDir("convert_cli");
  std::string imu;  // rates where increments belong
  for (int k = 0; k < 100; ++k) imu += Fixed(357000 + 0.005 * k, 3) + " 0.01 0.02 0.03 0.1 0.2 -9.81\n";
  test::WriteFile(dir + "/imu.txt", imu);
  test::WriteFile(dir + "/gnss.txt", "357000.1 30.5 114.5 20 0.1 0.1 0.2\n");
  const CliResult r = RunCliInChild({"convert", "--format", "i2nav", "--imu", dir + "/imu.txt", "--gnss",
                                     dir + "/gnss.txt", "--out", dir + "/log.txt"},
                                    dir);
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err.rfind("gins: error: " + dir + "/imu.txt:1: the velocity columns look like accelerations", 0), 0u)
      << r.err;
  EXPECT_FALSE(fs::exists(dir + "/log.txt"));
}

TEST(ConvertCli, SimulatedI2navDriveConvertsAndRunsInEskf) {
  const std::string dir = test::MakeTempDir("convert_cli");
  const std::string config = dir + "/config.yaml", sim = dir + "/sim";
  test::WriteFile(config, kConfig);
  ASSERT_EQ(RunCliInChild({"simulate", "--config", config, "--out", sim}, dir).code, 0);
  const std::string imu = dir + "/ADIS16465.txt", gnss = dir + "/GNSS_RTK.pos", log = dir + "/converted.txt";
  size_t n_imu = 0;
  WriteI2nav(sim + "/log.txt", imu, gnss, &n_imu);
  ASSERT_GT(n_imu, 7000u);

  const CliResult convert =
      RunCliInChild({"convert", "--format", "i2nav", "--imu", imu, "--gnss", gnss, "--out", log}, dir);
  ASSERT_EQ(convert.code, 0) << convert.err;
  std::printf("%s", convert.out.c_str());
  EXPECT_NE(convert.out.find("gins convert: i2nav -> " + log + " (" + std::to_string(n_imu) + " IMU, 41 GNSS records"),
            std::string::npos)
      << convert.out;
  EXPECT_EQ(convert.out.find("skipped"), std::string::npos) << convert.out;
  EXPECT_EQ(convert.out.find("warning"), std::string::npos) << convert.out;

  InputOptions stop;  // the converted log reads back without damage
  stop.on_error = InputErrorPolicy::kStop;
  LogReader reader(log, stop);
  for (LogRecord r; reader.Next(&r);) {
  }
  EXPECT_EQ(reader.stats().imu, n_imu);

  const std::string log_with_wheels = dir + "/converted_with_wheels.txt", out = dir + "/out";
  test::WriteFile(log_with_wheels, WithWheels(log, sim + "/log.txt"));
  const CliResult run = RunCliInChild({"run", "--config", config, "--log", log_with_wheels, "--out", out, "--mode",
                                       "eskf", "--truth", sim + "/truth.csv"},
                                      dir);
  ASSERT_EQ(run.code, 0) << run.err;
  const nlohmann::json s = nlohmann::json::parse(test::ReadFile(out + "/summary.json"));
  EXPECT_EQ(s["input"]["records"]["imu"].get<uint64_t>(), n_imu);
  EXPECT_EQ(s["input"]["records"]["gnss"].get<uint64_t>(), 41u);
  EXPECT_TRUE(s["input"]["skipped"].empty()) << s["input"]["skipped"].dump();
  EXPECT_EQ(s["initialization"]["heading_source"], "motion");
  const auto& acc = s["accuracy"]["eskf"];
  std::printf("eskf on the converted log: %s\n", acc.dump().c_str());
  EXPECT_GT(acc["samples"].get<uint64_t>(), 5000u);
  EXPECT_LT(acc["rmse_horizontal_m"].get<double>(), 0.3);
  EXPECT_LT(acc["rmse_heading_deg"].get<double>(), 2.0);
}

}  // namespace
}  // namespace gins
