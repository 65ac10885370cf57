// `gins convert` end to end: usage, a refused file (exit 1, the line named, no output), and a simulated
// drive written as i2Nav files, as an RTKLIB .pos and as NMEA, converted, and run through
// `gins run --mode eskf` against its truth.
//
// RunCli runs in a forked child (as in cli_test.cc, whose runner is private to that file): glog allows one
// InitGoogleLogging per process, and a child keeps one call's global state from the next.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "apps/cli.h"
#include "core/io/log_reader.h"
#include "core/time_scales.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

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
constexpr const char* kConfig = R"(# convert_cli_test: the conversion round trip
simulate:
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
    if (r.is<GnssRecord>()) {
      const GnssRecord& g = r.get<GnssRecord>();
      gnss += Fixed(g.t, 3) + " " + Fixed(g.lat_deg, 11) + " " + Fixed(g.lon_deg, 11) + " " + Fixed(g.alt_m, 4) + " " +
              Sci(g.sigma_enu.y()) + " " + Sci(g.sigma_enu.x()) + " " + Sci(g.sigma_enu.z()) + "\n";
    }
    if (!r.is<ImuSample>()) continue;
    const ImuSample& s = r.get<ImuSample>();
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
  std::vector<std::pair<double, std::string>> wheel;
  for (const auto& line : Lines(test::ReadFile(sim_log))) {
    if (line.rfind("ODOM ", 0) == 0) wheel.emplace_back(std::stod(line.substr(5)), line);
  }
  std::string merged;
  size_t i = 0;
  for (const auto& line : Lines(test::ReadFile(converted))) {
    const size_t space = line.find(' ');
    const double t = line[0] == '#' ? 0.0 : std::stod(line.substr(space + 1));
    for (; i < wheel.size() && wheel[i].first < t; ++i) merged += wheel[i].second + "\n";
    merged += line + "\n";
  }
  for (; i < wheel.size(); ++i) merged += wheel[i].second + "\n";
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
  EXPECT_EQ(CountOf<ImuSample>(reader.stats().records), n_imu);

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

// The same kind of drive on an absolute GPS clock (2025-08-28, GPS seconds since 1980-01-06), as the GNSS
// formats carry dates: its log stands for the logger's IMU/wheel log, its fixes for the receiver's file.
constexpr const char* kGpsConfig = R"(# convert_cli_test: GNSS formats round trip
simulate:
  seed: 11
  start_time_s: 1440437000
  origin: [40.0967, -105.1471, 1584.0]
  initial_heading_deg: 30
  segments:
    - {duration_s: 10}
    - {duration_s: 8, accel_m_s2: 1.0}
    - {duration_s: 10, yaw_rate_deg_s: 6}
    - {duration_s: 12}
  imu_rate_hz: 100
  gnss_rate_hz: 1
)";

std::vector<GnssRecord> Fixes(const std::string& log) {
  LogReader reader(log, InputOptions{});
  std::vector<GnssRecord> fixes;
  for (LogRecord r; reader.Next(&r);) {
    if (r.is<GnssRecord>()) fixes.push_back(r.get<GnssRecord>());
  }
  return fixes;
}

// The fixes as rnx2rtkp writes them (GPST, week and seconds, Q 1, σ north east up).
std::string PosFile(const std::vector<GnssRecord>& fixes) {
  std::string pos =
      "%  GPST          latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)  "
      "sdeu(m)  sdun(m) age(s)  ratio\n";
  for (const GnssRecord& g : fixes) {
    const double week = std::floor(g.t / 604800.0);
    char line[256];
    std::snprintf(line, sizeof(line), "%.0f %.3f %.9f %.9f %.4f 1 20 %.4f %.4f %.4f 0 0 0 0.5 9.9\n", week,
                  g.t - week * 604800.0, g.lat_deg, g.lon_deg, g.alt_m, g.sigma_enu.y(), g.sigma_enu.x(),
                  g.sigma_enu.z());
    pos += line;
  }
  return pos;
}

std::string Nmea(const std::string& body) {
  unsigned x = 0;
  for (const char c : body) x ^= static_cast<unsigned char>(c);
  char hex[8];
  std::snprintf(hex, sizeof(hex), "*%02X\r\n", x);
  return "$" + body + hex;
}

// The fixes as a receiver's NMEA: RMC (date, no speed), GGA (quality 4, geoid separation 0), GST, HDT; UTC.
std::string NmeaFile(const std::vector<GnssRecord>& fixes) {
  std::string nmea;
  for (const GnssRecord& g : fixes) {
    const UtcCalendar c = ToUtcCalendar(GpsToUnixUtc(g.t));
    char time[16], date[16], lat[32], lon[32], gst[128], hdt[32];
    std::snprintf(time, sizeof(time), "%02d%02d%05.2f", c.hour, c.minute, c.second);
    std::snprintf(date, sizeof(date), "%02d%02d%02d", c.day, c.month, c.year % 100);
    const double alat = std::abs(g.lat_deg), alon = std::abs(g.lon_deg);
    std::snprintf(lat, sizeof(lat), "%02d%010.7f,%c", static_cast<int>(alat), (alat - std::floor(alat)) * 60.0,
                  g.lat_deg < 0 ? 'S' : 'N');
    std::snprintf(lon, sizeof(lon), "%03d%010.7f,%c", static_cast<int>(alon), (alon - std::floor(alon)) * 60.0,
                  g.lon_deg < 0 ? 'W' : 'E');
    std::snprintf(gst, sizeof(gst), "GNGST,%s,0.5,0.03,0.02,0.0,%.4f,%.4f,%.4f", time, g.sigma_enu.y(), g.sigma_enu.x(),
                  g.sigma_enu.z());
    std::snprintf(hdt, sizeof(hdt), "GNHDT,%.3f,T", g.heading_deg);
    nmea += Nmea(std::string("GNRMC,") + time + ",A," + lat + "," + lon + ",,," + date + ",,,R");
    nmea += Nmea(std::string("GNGGA,") + time + "," + lat + "," + lon + ",4,20,0.7," + Fixed(g.alt_m, 4) +
                 ",M,0.0,M,1.0,0001");
    nmea += Nmea(gst);
    if (g.heading_valid) nmea += Nmea(hdt);
  }
  return nmea;
}

TEST(ConvertCli, OptionsOfAnotherFormatAreUsageErrors) {
  const std::string dir = test::MakeTempDir("convert_cli");
  const std::vector<std::string> base = {"convert", "--imu", "a", "--gnss", "b", "--out", "c"};
  for (const auto& extra : std::vector<std::vector<std::string>>{
           {"--format", "i2nav", "--min-quality", "fix"},
           {"--format", "nmea", "--imu-data", "rates"},
           {"--format", "rtklib-pos", "--date", "2025-08-28"},
           {"--format", "rtklib-pos", "--gnss-columns", "t=1,lat=2,lon=3,h=4"},
           {"--format", "csv"},
           {"--format", "nmea", "--wheel", "w.csv"},
           {"--format", "nmea", "--date", "2025-02-30"},
           {"--format", "nmea", "--min-quality", "best"},
           {"--format", "rtklib-pos", "--velocity-sigma", "0.2"},
           {"--format", "csv", "--gnss-columns", "t=1,lat=2,lon=3"},
           {"--format", "nmea", "--imu-columns", "t=1,gx=2"},
       }) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    const CliResult r = RunCliInChild(args, dir);
    EXPECT_EQ(r.code, 2) << extra[1] << " " << extra[2] << ": " << r.err;
  }
  const CliResult help = RunCliInChild({"convert", "--help"}, dir);
  EXPECT_NE(help.out.find("rtklib-pos RTKLIB .pos"), std::string::npos) << help.out;
}

TEST(ConvertCli, DamagedNmeaStopsNamingFileLineAndReasonAndWritesNothing) {
  const std::string dir = test::MakeTempDir("convert_cli");
  test::WriteFile(dir + "/imu.txt", "IMU 1440437439 0 0 0 0 0 9.8\nIMU 1440437440 0 0 0 0 0 9.8\n");
  std::string gga = Nmea("GNGGA,173021.00,4005.8029656,N,10508.8279915,W,1,15,1.0,1600.656,M,-16.288,M,,");
  gga[gga.size() - 3] ^= 1;  // a flipped bit in the checksum
  test::WriteFile(dir + "/gnss.nmea", Nmea("GNRMC,173021.00,A,4005.8029656,N,10508.8279915,W,,,280825,,,A") + gga);
  const CliResult r = RunCliInChild({"convert", "--format", "nmea", "--gnss", dir + "/gnss.nmea", "--imu",
                                     dir + "/imu.txt", "--out", dir + "/log.txt", "--on-error", "stop"},
                                    dir);
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err.rfind("gins: error: " + dir + "/gnss.nmea:2: bad_checksum: checksum '", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/log.txt"));
}

TEST(ConvertCli, SimulatedDriveAsRtklibPosAndAsNmeaConvertsAndRunsInEskf) {
  const std::string dir = test::MakeTempDir("convert_cli");
  const std::string config = dir + "/config.yaml", sim = dir + "/sim";
  test::WriteFile(config, kGpsConfig);
  ASSERT_EQ(RunCliInChild({"simulate", "--config", config, "--out", sim}, dir).code, 0);
  const std::vector<GnssRecord> fixes = Fixes(sim + "/log.txt");
  ASSERT_EQ(fixes.size(), 41u);
  test::WriteFile(dir + "/sol.pos", PosFile(fixes));
  test::WriteFile(dir + "/rx.nmea", NmeaFile(fixes));
  for (const auto& [format, file] :
       std::vector<std::pair<std::string, std::string>>{{"rtklib-pos", "sol.pos"}, {"nmea", "rx.nmea"}}) {
    const std::string log = dir + "/" + format + ".txt", out = dir + "/out_" + format;
    const CliResult convert = RunCliInChild(
        {"convert", "--format", format, "--gnss", dir + "/" + file, "--imu", sim + "/log.txt", "--out", log}, dir);
    ASSERT_EQ(convert.code, 0) << convert.err;
    std::printf("%s", convert.out.c_str());
    EXPECT_NE(convert.out.find(" IMU, 400 ODOM, 41 GNSS, 0 GVEL records"), std::string::npos) << convert.out;
    EXPECT_NE(convert.out.find("dropped its own 41 GNSS and 0 GVEL records"), std::string::npos) << convert.out;
    EXPECT_EQ(convert.out.find("skipped"), std::string::npos) << convert.out;
    const std::vector<GnssRecord> converted = Fixes(log);
    ASSERT_EQ(converted.size(), fixes.size());
    for (size_t i = 0; i < fixes.size(); ++i) {  // the files' rounding: 1e-9 deg, 1e-7' (0.2 mm), 0.1 mm
      EXPECT_EQ(converted[i].t, fixes[i].t) << format << " " << i;
      EXPECT_NEAR(converted[i].lat_deg, fixes[i].lat_deg, 2e-9) << format << " " << i;
      EXPECT_NEAR(converted[i].lon_deg, fixes[i].lon_deg, 2e-9) << format << " " << i;
      EXPECT_NEAR(converted[i].alt_m, fixes[i].alt_m, 1e-4) << format << " " << i;
      EXPECT_NEAR((converted[i].sigma_enu - fixes[i].sigma_enu).norm(), 0.0, 1e-4) << format << " " << i;
      EXPECT_EQ(converted[i].heading_valid, format == "nmea" && fixes[i].heading_valid) << format << " " << i;
    }
    const CliResult run = RunCliInChild(
        {"run", "--config", config, "--log", log, "--out", out, "--mode", "eskf", "--truth", sim + "/truth.csv"}, dir);
    ASSERT_EQ(run.code, 0) << run.err;
    const nlohmann::json s = nlohmann::json::parse(test::ReadFile(out + "/summary.json"));
    EXPECT_EQ(s["input"]["records"]["gnss"].get<uint64_t>(), 41u);
    EXPECT_TRUE(s["input"]["skipped"].empty()) << s["input"]["skipped"].dump();
    const auto& acc = s["accuracy"]["eskf"];
    std::printf("eskf on the %s log: %s\n", format.c_str(), acc.dump().c_str());
    EXPECT_GT(acc["samples"].get<uint64_t>(), 2500u);
    EXPECT_LT(acc["rmse_horizontal_m"].get<double>(), 0.3);
    EXPECT_LT(acc["rmse_heading_deg"].get<double>(), 2.0);
  }
}

}  // namespace
}  // namespace gins
