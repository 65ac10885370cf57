#include "config/config_loader.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

const std::string kConfigDir = GINS_SOURCE_DIR "/config/";

// ---- Field-by-field comparison -----------------------------------------------------------------------------
// Exact equality throughout: the loader's conversions repeat the defaults' arithmetic, and the writer picks
// digits that load back to the same double.

bool Same(double a, double b) { return a == b; }
bool Same(int a, int b) { return a == b; }
bool Same(unsigned a, unsigned b) { return a == b; }
bool Same(bool a, bool b) { return a == b; }
bool Same(const std::string& a, const std::string& b) { return a == b; }
bool Same(InputErrorPolicy a, InputErrorPolicy b) { return a == b; }
bool Same(const Vec3& a, const Vec3& b) { return a == b; }
bool Same(const Mat3& a, const Mat3& b) { return a == b; }
bool Same(const GeodeticPoint& a, const GeodeticPoint& b) {
  return a.lat_deg == b.lat_deg && a.lon_deg == b.lon_deg && a.alt_m == b.alt_m;
}
bool Same(const std::optional<GeodeticPoint>& a, const std::optional<GeodeticPoint>& b) {
  return a.has_value() == b.has_value() && (!a || Same(*a, *b));
}
bool Same(const std::vector<SimSegment>& a, const std::vector<SimSegment>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].duration != b[i].duration || a[i].accel != b[i].accel || a[i].yaw_rate != b[i].yaw_rate ||
        a[i].grade != b[i].grade) {
      return false;
    }
  }
  return true;
}
bool Same(const std::vector<std::pair<double, double>>& a, const std::vector<std::pair<double, double>>& b) {
  return a == b;
}
bool Same(const GnssOptions::PeriodicOutages& a, const GnssOptions::PeriodicOutages& b) {
  return a.first_start == b.first_start && a.duration == b.duration && a.period == b.period;
}

struct Comparison {
  int fields = 0;
  std::vector<std::string> differing;
};

// Every field of Options: a new field must be added here, to the loader, the writer and default.yaml.
Comparison Compare(const Options& a, const Options& b) {
  Comparison c;
  auto field = [&c](const char* name, const auto& x, const auto& y) {
    ++c.fields;
    if (!Same(x, y)) c.differing.push_back(name);
  };
#define GINS_FIELD(path) field(#path, a.path, b.path)
  GINS_FIELD(input.on_error);
  GINS_FIELD(input.max_errors);
  GINS_FIELD(input.max_line_length);
  GINS_FIELD(input.max_time_jump);
  GINS_FIELD(sensors.imu.R_b_imu);
  GINS_FIELD(sensors.imu.gyro_noise_density);
  GINS_FIELD(sensors.imu.acc_noise_density);
  GINS_FIELD(sensors.imu.gyro_bias_rw);
  GINS_FIELD(sensors.imu.acc_bias_rw);
  GINS_FIELD(sensors.imu.init_gyro_bias_sigma);
  GINS_FIELD(sensors.imu.init_acc_bias_sigma);
  GINS_FIELD(sensors.imu.max_gap);
  GINS_FIELD(sensors.imu.max_gyro);
  GINS_FIELD(sensors.imu.max_acc);
  GINS_FIELD(sensors.gnss.lever_b);
  GINS_FIELD(sensors.gnss.mount_yaw);
  GINS_FIELD(sensors.gnss.sigma_enu);
  GINS_FIELD(sensors.gnss.min_sigma);
  GINS_FIELD(sensors.gnss.heading_sigma);
  GINS_FIELD(sensors.gnss.use_heading);
  GINS_FIELD(sensors.gnss.gate_probability);
  GINS_FIELD(sensors.gnss.origin);
  GINS_FIELD(sensors.gnss.outages);
  GINS_FIELD(sensors.gnss.periodic_outages);
  GINS_FIELD(sensors.wheel.enabled);
  GINS_FIELD(sensors.wheel.radius);
  GINS_FIELD(sensors.wheel.pulses_per_rev);
  GINS_FIELD(sensors.wheel.interval);
  GINS_FIELD(sensors.wheel.speed_sigma);
  GINS_FIELD(sensors.wheel.gate_probability);
  GINS_FIELD(sensors.wheel.scale_sigma);
  GINS_FIELD(sensors.wheel.scale_rw);
  GINS_FIELD(sensors.wheel.estimate_scale);
  GINS_FIELD(sensors.wheel.lever_b);
  GINS_FIELD(sensors.wheel.track);
  GINS_FIELD(sensors.vehicle.nonholonomic);
  GINS_FIELD(sensors.vehicle.nhc_sigma);
  GINS_FIELD(sensors.vehicle.nhc_rate);
  GINS_FIELD(sensors.gravity.earth_rotation);
  GINS_FIELD(sensors.gravity.use_normal_gravity);
  GINS_FIELD(sensors.gravity.magnitude);
  GINS_FIELD(init.static_duration);
  GINS_FIELD(init.max_wait);
  GINS_FIELD(init.wait_for_heading);
  GINS_FIELD(init.max_attitude_sigma);
  GINS_FIELD(eskf.estimate_gravity);
  GINS_FIELD(eskf.gravity_sigma);
  GINS_FIELD(smoother.window_size);
  GINS_FIELD(smoother.max_keyframe_interval);
  GINS_FIELD(smoother.min_keyframe_interval);
  GINS_FIELD(smoother.linear_solver);
  GINS_FIELD(smoother.max_iterations);
  GINS_FIELD(smoother.num_threads);
  GINS_FIELD(smoother.bias_reintegrate_threshold);
  GINS_FIELD(standstill.enabled);
  GINS_FIELD(standstill.window);
  GINS_FIELD(standstill.max_gyro_std);
  GINS_FIELD(standstill.max_acc_std);
  GINS_FIELD(standstill.velocity_sigma);
  GINS_FIELD(standstill.max_speed);
  GINS_FIELD(watchdog.enabled);
  GINS_FIELD(watchdog.max_reject);
  GINS_FIELD(watchdog.max_position_sigma);
  GINS_FIELD(simulate.seed);
  GINS_FIELD(simulate.start_time);
  GINS_FIELD(simulate.origin);
  GINS_FIELD(simulate.initial_yaw);
  GINS_FIELD(simulate.segments);
  GINS_FIELD(simulate.imu_rate);
  GINS_FIELD(simulate.gnss_rate);
  GINS_FIELD(simulate.wheel_rate);
  GINS_FIELD(simulate.gyro_noise_density);
  GINS_FIELD(simulate.acc_noise_density);
  GINS_FIELD(simulate.gyro_bias_rw);
  GINS_FIELD(simulate.acc_bias_rw);
  GINS_FIELD(simulate.gyro_turn_on_bias);
  GINS_FIELD(simulate.acc_turn_on_bias);
  GINS_FIELD(simulate.gnss_sigma_enu);
  GINS_FIELD(simulate.write_gnss_sigma);
  GINS_FIELD(simulate.heading_sigma);
  GINS_FIELD(simulate.heading_invalid_fraction);
  GINS_FIELD(simulate.gnss_outages);
  GINS_FIELD(simulate.gnss_outlier_probability);
  GINS_FIELD(simulate.gnss_outlier_magnitude);
  GINS_FIELD(simulate.lever_b);
  GINS_FIELD(simulate.mount_yaw);
  GINS_FIELD(simulate.wheel_radius);
  GINS_FIELD(simulate.pulses_per_rev);
  GINS_FIELD(simulate.wheel_scale);
  GINS_FIELD(simulate.wheel_speed_noise);
  GINS_FIELD(simulate.track_width);
#undef GINS_FIELD
  return c;
}

std::string Join(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += x + " ";
  return s;
}

void ExpectSameOptions(const Options& a, const Options& b) {
  EXPECT_TRUE(Compare(a, b).differing.empty()) << "differing fields: " << Join(Compare(a, b).differing);
}

// Every field set away from its default, from round user numbers converted the way the comments say (so
// the values are what a config file would produce).
Options NonDefaultOptions() {
  Options o;
  o.input.on_error = InputErrorPolicy::kStop;
  o.input.max_errors = 7;
  o.input.max_line_length = 300;
  o.input.max_time_jump = 3600.0;
  o.sensors.imu.R_b_imu << 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0;  // a proper rotation, not a named one
  o.sensors.imu.gyro_noise_density = 0.15 * kDegToRad / 60.0;
  o.sensors.imu.acc_noise_density = 0.03 / 60.0;
  o.sensors.imu.gyro_bias_rw = 3.0 * kDegToRad / 3600.0 / 60.0;
  o.sensors.imu.acc_bias_rw = 0.004 / 60.0;
  o.sensors.imu.init_gyro_bias_sigma = 50.0 * kDegToRad / 3600.0;
  o.sensors.imu.init_acc_bias_sigma = 0.02;
  o.sensors.imu.max_gap = 0.25;
  o.sensors.imu.max_gyro = 10.0;
  o.sensors.imu.max_acc = 80.0;
  o.sensors.gnss.lever_b = Vec3(0.5, -0.25, 1.125);
  o.sensors.gnss.mount_yaw = -90.0 * kDegToRad;
  o.sensors.gnss.sigma_enu = Vec3(1.5, 1.6, 3.1);
  o.sensors.gnss.min_sigma = 0.3;
  o.sensors.gnss.heading_sigma = 1.5 * kDegToRad;
  o.sensors.gnss.use_heading = false;
  o.sensors.gnss.gate_probability = 0.0;
  o.sensors.gnss.origin = GeodeticPoint{39.668529021, -79.970733949, 287.8759};
  o.sensors.gnss.outages = {{300.0, 60.0}, {512.5, 30.0}};
  o.sensors.gnss.periodic_outages = {250.0, 60.0, 180.0};
  o.sensors.wheel.enabled = false;
  o.sensors.wheel.radius = 0.11;
  o.sensors.wheel.pulses_per_rev = 2048;
  o.sensors.wheel.interval = 0.05;
  o.sensors.wheel.speed_sigma = 0.07;
  o.sensors.wheel.gate_probability = 0.999;
  o.sensors.wheel.scale_sigma = 0.02;
  o.sensors.wheel.scale_rw = 3e-5;
  o.sensors.wheel.estimate_scale = false;
  o.sensors.wheel.lever_b = Vec3(-1.5, 0.0, -0.3);
  o.sensors.wheel.track = 1.55;
  o.sensors.vehicle.nonholonomic = false;
  o.sensors.vehicle.nhc_sigma = 0.3;
  o.sensors.vehicle.nhc_rate = 5.0;
  o.sensors.gravity.earth_rotation = false;
  o.sensors.gravity.use_normal_gravity = false;
  o.sensors.gravity.magnitude = 9.7936;
  o.init.static_duration = 5.0;
  o.init.max_wait = 60.0;
  o.init.wait_for_heading = true;
  o.init.max_attitude_sigma = 2.5 * kDegToRad;
  o.eskf.estimate_gravity = false;
  o.eskf.gravity_sigma = 0.001;
  o.smoother.window_size = 20;
  o.smoother.max_keyframe_interval = 0.5;
  o.smoother.min_keyframe_interval = 0.25;
  o.smoother.linear_solver = "dense_schur";
  o.smoother.max_iterations = 4;
  o.smoother.num_threads = 4;
  o.smoother.bias_reintegrate_threshold = 0.0;
  o.standstill.enabled = false;
  o.standstill.window = 2.0;
  o.standstill.max_gyro_std = 1.5 * kDegToRad;
  o.standstill.max_acc_std = 0.3;
  o.standstill.velocity_sigma = 0.02;
  o.standstill.max_speed = 0.25;
  o.watchdog.enabled = false;
  o.watchdog.max_reject = 30.0;
  o.watchdog.max_position_sigma = 500.0;
  SimOptions& s = o.simulate;
  s.seed = 4294967295u;
  s.start_time = 1594593409.000679;
  s.origin = GeodeticPoint{-33.9, 151.2, 40.0};
  s.initial_yaw = CompassDegToEnuYaw(30.0);
  s.segments = {{20.0, 0.0, 0.0, 0.0}, {10.0, 1.0, 9.0 * kDegToRad, 3.0 * kDegToRad}, {7.5, -0.75, 0.0, 0.0}};
  s.imu_rate = 200.0;
  s.gnss_rate = 10.0;
  s.wheel_rate = 20.0;
  s.gyro_noise_density = 0.0;
  s.acc_noise_density = 0.1 / 60.0;
  s.gyro_bias_rw = 1.0 * kDegToRad / 3600.0 / 60.0;
  s.acc_bias_rw = 0.0;
  s.gyro_turn_on_bias = 200.0 * kDegToRad / 3600.0;
  s.acc_turn_on_bias = 0.05;
  s.gnss_sigma_enu = Vec3(1.0, 1.0, 2.0);
  s.write_gnss_sigma = false;
  s.heading_sigma = 0.0;
  s.heading_invalid_fraction = 1.0;
  s.gnss_outages = {{40.0, 15.0}, {100.5, 2.0}};
  s.gnss_outlier_probability = 0.01;
  s.gnss_outlier_magnitude = 5.0;
  s.lever_b = Vec3(1.0, 0.0, 0.5);
  s.mount_yaw = 90.0 * kDegToRad;
  s.wheel_radius = 0.3;
  s.pulses_per_rev = 100.0;
  s.wheel_scale = 1.02;
  s.wheel_speed_noise = 0.0;
  s.track_width = 0.6;
  return o;
}

// Key paths of a YAML document's mappings (lists are leaves).
void CollectKeys(const YAML::Node& n, const std::string& prefix, std::set<std::string>* keys) {
  if (!n.IsMap()) return;
  for (const auto& kv : n) {
    const std::string path = prefix.empty() ? kv.first.Scalar() : prefix + "." + kv.first.Scalar();
    keys->insert(path);
    CollectKeys(kv.second, path, keys);
  }
}

Options Load(const std::string& yaml) { return LoadOptionsFromString(yaml, "test.yaml"); }

// The ConfigError message for `yaml` ("" when it loads).
std::string ErrorOf(const std::string& yaml) {
  try {
    Load(yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

// ---- default.yaml and the scenario configs -----------------------------------------------------------------

TEST(ConfigLoaderTest, DefaultYamlEqualsInClassDefaults) {
  const Options loaded = LoadOptions(kConfigDir + "default.yaml");
  const Options defaults;
  ExpectSameOptions(loaded, defaults);
}

TEST(ConfigLoaderTest, DefaultYamlDocumentsEveryKeyTheWriterWrites) {
  std::set<std::string> documented, written;
  CollectKeys(YAML::LoadFile(kConfigDir + "default.yaml"), "", &documented);
  CollectKeys(YAML::Load(OptionsToYaml(Options())), "", &written);
  EXPECT_EQ(documented, written);
}

TEST(ConfigLoaderTest, EmptyOrCommentOnlyTextGivesDefaults) {
  ExpectSameOptions(Load(""), Options());
  ExpectSameOptions(Load("# nothing\n\n"), Options());
  ExpectSameOptions(Load("imu:\n  # all commented out\ngnss:\n"), Options());
}

TEST(ConfigLoaderTest, WvuRoverConfigLoads) {
  const Options o = LoadOptions(kConfigDir + "wvu_rover.yaml");
  EXPECT_FALSE(o.sensors.gnss.use_heading);
  EXPECT_FALSE(o.init.wait_for_heading);
  EXPECT_EQ(o.sensors.gnss.lever_b, Vec3::Zero());
  EXPECT_EQ(o.sensors.wheel.radius, 0.11);
  EXPECT_EQ(o.sensors.wheel.pulses_per_rev, 1024.0);
  EXPECT_EQ(o.sensors.imu.R_b_imu, Mat3::Identity());
  EXPECT_DOUBLE_EQ(o.init.static_duration, 2.0);
}

// The outage scenario is the defaults plus three 60 s simulated GNSS outages.
TEST(ConfigLoaderTest, OutagesScenarioIsDefaultsPlusOutages) {
  const Options o = LoadOptions(kConfigDir + "outages_3x60s.yaml");
  Options expected;
  expected.sensors.gnss.outages = {{300.0, 60.0}, {650.0, 60.0}, {850.0, 60.0}};
  ExpectSameOptions(o, expected);
}

TEST(ConfigLoaderTest, SimSampleConfigLoadsAndDescribesTheSampleDrive) {
  const Options o = LoadOptions(kConfigDir + "sim_sample.yaml");
  // Same run sections as the defaults.
  Options expected = o;
  const Options defaults;
  expected.input = defaults.input;
  expected.sensors.imu = defaults.sensors.imu;
  expected.sensors.gnss = defaults.sensors.gnss;
  expected.sensors.wheel = defaults.sensors.wheel;
  expected.sensors.gravity = defaults.sensors.gravity;
  expected.init = defaults.init;
  expected.eskf = defaults.eskf;
  expected.smoother = defaults.smoother;
  expected.standstill = defaults.standstill;
  expected.watchdog = defaults.watchdog;
  ExpectSameOptions(o, expected);

  const SimOptions& s = o.simulate;
  EXPECT_EQ(s.imu_rate, 100.0);
  EXPECT_EQ(s.gnss_rate, 1.0);
  EXPECT_EQ(s.wheel_rate, 10.0);
  ASSERT_FALSE(s.segments.empty());
  EXPECT_EQ(s.segments.front().accel, 0.0);
  EXPECT_GE(s.segments.front().duration, 20.0);  // standstill first, for initialisation
  double t = 0.0, v = 0.0, v_max = 0.0, stop_duration = 0.0, yaw_left = 0.0, yaw_right = 0.0;
  double grade_max = 0.0, grade_min = 0.0;
  for (const SimSegment& seg : s.segments) {
    v += seg.accel * seg.duration;
    EXPECT_GE(v, -1e-9) << "segment ending at " << t + seg.duration << " s reverses";
    if (t > 0.0 && seg.accel == 0.0 && std::abs(v) < 1e-9) stop_duration += seg.duration;
    t += seg.duration;
    v_max = std::max(v_max, v);
    yaw_left = std::max(yaw_left, seg.yaw_rate);
    yaw_right = std::min(yaw_right, seg.yaw_rate);
    grade_max = std::max(grade_max, seg.grade);
    grade_min = std::min(grade_min, seg.grade);
  }
  EXPECT_NEAR(t, 180.0, 10.0);
  EXPECT_NEAR(v_max, 15.0, 1e-9);
  EXPECT_GE(stop_duration, 10.0);
  EXPECT_GT(yaw_left, 0.0);
  EXPECT_LT(yaw_right, 0.0);
  EXPECT_GT(grade_max, 0.0);
  EXPECT_LT(grade_min, 0.0);
  ASSERT_EQ(s.gnss_outages.size(), 1u);
  EXPECT_EQ(s.gnss_outages[0].second, 15.0);
  EXPECT_GT(s.gnss_outlier_probability, 0.0);
}

// ---- Units ----------------------------------------------------------------------------------------------

TEST(ConfigLoaderTest, ConvertsUsersUnitsToSi) {
  const Options o = Load(R"(
imu:
  gyro_noise_deg_sqrt_h: 0.15
  acc_noise_m_s_sqrt_h: 0.03
  gyro_bias_rw_deg_h_sqrt_h: 3
  acc_bias_rw_m_s2_sqrt_h: 0.006
  init_gyro_bias_sigma_deg_h: 36
gnss:
  mount_yaw_deg: 90
  heading_sigma_deg: 2
init:
  max_attitude_sigma_deg: 1
simulate:
  initial_heading_deg: 0
  segments: [{duration_s: 4, yaw_rate_deg_s: 9, grade_deg: -3}]
  gyro_turn_on_bias_deg_h: 360
)");
  const double rel = 1e-15;
  // deg/√h → rad/s/√Hz: ×π/180/60.  0.15 deg/√h = 4.3633e-5 rad/s/√Hz.
  EXPECT_NEAR(o.sensors.imu.gyro_noise_density, 0.15 * kPi / 180.0 / 60.0, rel * 1e-4);
  EXPECT_NEAR(o.sensors.imu.gyro_noise_density, 4.36332e-5, 1e-10);
  // m/s/√h → m/s²/√Hz: /60.
  EXPECT_NEAR(o.sensors.imu.acc_noise_density, 0.0005, rel);
  // deg/h/√h → rad/s/√s: ×π/180/3600/60.
  EXPECT_NEAR(o.sensors.imu.gyro_bias_rw, 3.0 * kPi / 180.0 / 216000.0, rel * 1e-6);
  // m/s²/√h → m/s²/√s: /60.
  EXPECT_NEAR(o.sensors.imu.acc_bias_rw, 1e-4, rel);
  // deg/h → rad/s: 36 deg/h = 0.01 deg/s.
  EXPECT_NEAR(o.sensors.imu.init_gyro_bias_sigma, 0.01 * kPi / 180.0, rel);
  EXPECT_NEAR(o.simulate.gyro_turn_on_bias, 0.1 * kPi / 180.0, rel);
  EXPECT_NEAR(o.sensors.gnss.mount_yaw, kPi / 2.0, rel);
  EXPECT_NEAR(o.sensors.gnss.heading_sigma, 2.0 * kPi / 180.0, rel);
  EXPECT_NEAR(o.init.max_attitude_sigma, kPi / 180.0, rel);
  ASSERT_EQ(o.simulate.segments.size(), 1u);
  EXPECT_NEAR(o.simulate.segments[0].yaw_rate, 9.0 * kPi / 180.0, rel);
  EXPECT_NEAR(o.simulate.segments[0].grade, -3.0 * kPi / 180.0, rel);
  EXPECT_EQ(o.simulate.segments[0].accel, 0.0);
  // Compass heading 0 (north) is ENU yaw +90°.
  EXPECT_NEAR(o.simulate.initial_yaw, kPi / 2.0, rel);
}

TEST(ConfigLoaderTest, CompassHeadingToEnuYaw) {
  EXPECT_NEAR(Load("simulate: {initial_heading_deg: 90}").simulate.initial_yaw, 0.0, 1e-15);          // east
  EXPECT_NEAR(Load("simulate: {initial_heading_deg: 180}").simulate.initial_yaw, -kPi / 2.0, 1e-15);  // south
  EXPECT_NEAR(Load("simulate: {initial_heading_deg: 315}").simulate.initial_yaw, 3.0 * kPi / 4.0, 1e-15);
}

TEST(ConfigLoaderTest, ImuAxesNamesAndMatrices) {
  const Vec3 v_imu(1.0, 2.0, 3.0);
  EXPECT_EQ(Load("imu: {axes: FLU}").sensors.imu.R_b_imu * v_imu, Vec3(1.0, 2.0, 3.0));
  EXPECT_EQ(Load("imu: {axes: FRD}").sensors.imu.R_b_imu * v_imu, Vec3(1.0, -2.0, -3.0));
  // Right-forward-up: forward is logged y, left is minus logged x.
  EXPECT_EQ(Load("imu: {axes: RFU}").sensors.imu.R_b_imu * v_imu, Vec3(2.0, -1.0, 3.0));
  Mat3 R;
  R << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  EXPECT_EQ(Load("imu: {axes: [0, 0, 1, 1, 0, 0, 0, 1, 0]}").sensors.imu.R_b_imu, R);
  EXPECT_EQ(Load("imu: {axes: [[0, 0, 1], [1, 0, 0], [0, 1, 0]]}").sensors.imu.R_b_imu, R);
  // A 45° yaw typed with 7 digits is snapped to an exact rotation.
  const Mat3 R45 =
      Load("imu: {axes: [0.7071068, -0.7071068, 0, 0.7071068, 0.7071068, 0, 0, 0, 1]}").sensors.imu.R_b_imu;
  EXPECT_LT((R45 * R45.transpose() - Mat3::Identity()).norm(), 1e-14);
  EXPECT_NEAR(R45(0, 0), std::sqrt(0.5), 1e-7);
}

TEST(ConfigLoaderTest, GnssOriginNullOrPoint) {
  EXPECT_FALSE(Load("gnss: {origin: null}").sensors.gnss.origin.has_value());
  EXPECT_FALSE(Load("gnss:\n  origin:\n").sensors.gnss.origin.has_value());
  const auto origin = Load("gnss: {origin: [31.5, -120.25, -20]}").sensors.gnss.origin;
  ASSERT_TRUE(origin.has_value());
  EXPECT_EQ(origin->lat_deg, 31.5);
  EXPECT_EQ(origin->lon_deg, -120.25);
  EXPECT_EQ(origin->alt_m, -20.0);
}

TEST(ConfigLoaderTest, ZeroDisablesGates) {
  const Options o = Load("gnss: {gate_probability: 0}\nwheel: {gate_probability: 0}");
  EXPECT_EQ(o.sensors.gnss.gate_probability, 0.0);
  EXPECT_EQ(o.sensors.wheel.gate_probability, 0.0);
}

TEST(ConfigLoaderTest, EnumsAndBooleans) {
  const Options o = Load(
      "input: {on_error: stop}\ngravity: {model: fixed, magnitude_m_s2: 9.8}\n"
      "smoother: {linear_solver: dense_schur}\nwheel: {enabled: false}\nvehicle: {nonholonomic: false}");
  EXPECT_EQ(o.input.on_error, InputErrorPolicy::kStop);
  EXPECT_FALSE(o.sensors.gravity.use_normal_gravity);
  EXPECT_EQ(o.sensors.gravity.magnitude, 9.8);
  EXPECT_EQ(o.smoother.linear_solver, "dense_schur");
  EXPECT_FALSE(o.sensors.wheel.enabled);
  EXPECT_FALSE(o.sensors.vehicle.nonholonomic);
}

// ---- Errors ------------------------------------------------------------------------------------------------

struct ErrorCase {
  const char* yaml;
  std::vector<std::string> expected;  // substrings of the message
};

void ExpectErrors(const std::vector<ErrorCase>& cases) {
  for (const ErrorCase& c : cases) {
    const std::string message = ErrorOf(c.yaml);
    EXPECT_FALSE(message.empty()) << "loaded without error:\n" << c.yaml;
    for (const std::string& s : c.expected) {
      EXPECT_NE(message.find(s), std::string::npos) << "message '" << message << "' lacks '" << s << "'";
    }
  }
}

TEST(ConfigLoaderTest, UnknownKeysNameTheFullPathAndSuggest) {
  ExpectErrors({
      {"gnss:\n  lever_arm: [0, 0, 0]\n",
       {"test.yaml: gnss.lever_arm: unknown key (did you mean gnss.lever_arm_m?)", "(line 2)"}},
      {"smother:\n  window_size: 5\n", {"test.yaml: smother: unknown key (did you mean smoother?)"}},
      {"wheel: {radius: 0.3}", {"wheel.radius: unknown key (did you mean wheel.radius_m?)"}},
      {"imu: {gyro_noise_deg_sqrt_hz: 0.3}", {"imu.gyro_noise_deg_sqrt_hz", "did you mean imu.gyro_noise_deg_sqrt_h?"}},
      {"imu: {colour: blue}", {"imu.colour: unknown key"}},
      {"simulate:\n  segments:\n    - {duration_s: 3, yaw_rate: 2}\n",
       {"simulate.segments[0].yaw_rate: unknown key (did you mean simulate.segments[0].yaw_rate_deg_s?)"}},
      {"version: 2", {"test.yaml: version: unknown key"}},
  });
  // No suggestion when nothing is close.
  EXPECT_EQ(ErrorOf("eskf: {zzzzzzzzzz: 1}").find("did you mean"), std::string::npos);
}

TEST(ConfigLoaderTest, RemovedKeysSayWhyAndWhatReplacesThem) {
  ExpectErrors({{"smoother:\n  window_size: 5\n  gnss_loss_scale: 3.0\n",
                 {"test.yaml: smoother.gnss_loss_scale: removed key", "gnss.gate_probability", "(line 3)"}}});
  // Only at its own path: the same name elsewhere is an ordinary unknown key.
  ExpectErrors({{"batch: {gnss_loss_scale: 3.0}", {"batch.gnss_loss_scale: unknown key"}}});
  EXPECT_EQ(ErrorOf("batch: {gnss_loss_scale: 3.0}").find("removed"), std::string::npos);
}

TEST(ConfigLoaderTest, WrongTypesNameTheKeyAndWhatWasExpected) {
  ExpectErrors({
      {"wheel: {radius_m: abc}", {"test.yaml: wheel.radius_m: expected a number, got 'abc'"}},
      {"wheel: {radius_m: '0.3'}", {"wheel.radius_m: expected a number"}},  // quoted: a string
      {"wheel: {radius_m: [0.3]}", {"wheel.radius_m: expected a number, got a list of 1"}},
      {"gnss: {lever_arm_m: 0.5}", {"gnss.lever_arm_m: expected a list of 3 numbers"}},
      {"gnss: {sigma_m: [1, 2]}", {"gnss.sigma_m: expected a list of 3 numbers [east, north, up], got a list of 2"}},
      {"gnss: {sigma_m: [1, 2, x]}", {"gnss.sigma_m[2]: expected a number"}},
      {"gnss: {use_heading: maybe}", {"gnss.use_heading: expected true or false"}},
      {"smoother: {window_size: 2.5}", {"smoother.window_size: expected an integer, got '2.5'"}},
      {"imu: 5", {"test.yaml: imu: expected a mapping of keys"}},
      {"[1, 2, 3]", {"test.yaml: (top level): expected a mapping"}},
      {"imu: {max_gap_s: 0.5}\n---\nwheel: {radius_m: 0.3}\n", {"test.yaml: (top level): more than one YAML document"}},
      {"imu: {axes: [1, 0, 0]}", {"imu.axes: expected FLU, FRD, RFU or a rotation matrix as 9 numbers"}},
      {"imu: {axes: NED}", {"imu.axes: expected FLU, FRD, RFU", "'NED'"}},
      {"gnss: {origin: [31, 120]}", {"gnss.origin: expected a list of 3 numbers [lat_deg, lon_deg, alt_m]"}},
      {"simulate: {segments: {duration_s: 3}}", {"simulate.segments: expected a list"}},
      {"simulate: {segments: [5]}", {"simulate.segments[0]: expected a mapping"}},
      {"simulate: {gnss_outages_s: [[1, 2, 3]]}", {"simulate.gnss_outages_s[0]: expected [start_s, duration_s]"}},
      {"simulate: {gnss_outages_s: [10, 5]}", {"simulate.gnss_outages_s[0]: expected [start_s, duration_s]"}},
      {"simulate: {seed: -1}", {"simulate.seed: must be >= 0 (got -1)"}},
      {"simulate: {seed: 4294967296}", {"simulate.seed: must be <= 4294967295"}},
      {"smoother: {num_threads: 3000000000}", {"smoother.num_threads: must be <= 2147483647"}},
  });
}

TEST(ConfigLoaderTest, NonFiniteValuesAreErrors) {
  ExpectErrors({
      {"wheel: {radius_m: .nan}", {"wheel.radius_m: must be a finite number"}},
      {"imu: {max_gap_s: .inf}", {"imu.max_gap_s: must be a finite number"}},
      {"gnss: {lever_arm_m: [0, -.inf, 0]}", {"gnss.lever_arm_m[1]: must be a finite number"}},
      {"wheel: {radius_m: 1e999}", {"wheel.radius_m"}},
  });
}

TEST(ConfigLoaderTest, OutOfRangeValuesAreErrors) {
  ExpectErrors({
      {"gnss: {sigma_m: [0.05, 0, 0.1]}", {"gnss.sigma_m[1]: must be > 0 (got 0)"}},
      {"imu: {gyro_noise_deg_sqrt_h: -0.1}", {"imu.gyro_noise_deg_sqrt_h: must be > 0"}},
      {"wheel: {speed_sigma_m_s: 0}", {"wheel.speed_sigma_m_s: must be > 0"}},
      {"simulate: {imu_rate_hz: 0}", {"simulate.imu_rate_hz: must be > 0"}},
      {"gnss: {gate_probability: 1}", {"gnss.gate_probability: must be in (0, 1), or 0 to disable"}},
      {"wheel: {gate_probability: -0.5}", {"wheel.gate_probability: must be in (0, 1)"}},
      {"smoother: {window_size: 1}", {"smoother.window_size: must be >= 2 (got 1)"}},
      {"wheel: {radius_m: 0}", {"wheel.radius_m: must be > 0"}},
      {"wheel: {pulses_per_rev: 0}", {"wheel.pulses_per_rev: must be > 0"}},
      {"smoother: {num_threads: 0}", {"smoother.num_threads: must be >= 1"}},
      {"smoother: {max_iterations: 0}", {"smoother.max_iterations: must be >= 1"}},
      {"smoother: {linear_solver: dense_qr}",
       {"smoother.linear_solver: must be one of dense_schur, "
        "sparse_normal_cholesky, got 'dense_qr'"}},
      {"smoother: {linear_solver: dense_shur}", {"(did you mean dense_schur?)"}},
      {"input: {on_error: ignore}", {"input.on_error: must be one of skip, stop"}},
      {"gravity: {model: egm96}", {"gravity.model: must be one of normal, fixed"}},
      {"gravity: {magnitude_m_s2: 98.1}", {"gravity.magnitude_m_s2: must be within [9.7, 9.9]"}},
      {"gnss: {origin: [91, 0, 0]}", {"gnss.origin: not a plausible geodetic point"}},
      {"gnss: {lever_arm_m: [-170, -200, 0]}", {"gnss.lever_arm_m[0]: must be within [-100, 100]"}},
      {"imu: {axes: [1, 0, 0, 0, 1, 0, 0, 0, 2]}", {"imu.axes: not an orthonormal matrix"}},
      {"imu: {axes: [1, 0, 0, 0, 1, 0, 0, 0, -1]}", {"imu.axes: determinant is -1"}},
      {"simulate: {heading_invalid_fraction: 1.5}", {"simulate.heading_invalid_fraction: must be in [0, 1]"}},
      {"simulate: {gnss_outages_s: [[10, 0]]}", {"simulate.gnss_outages_s[0][1]: must be > 0"}},
      {"simulate: {segments: [{accel_m_s2: 1}]}", {"simulate.segments[0].duration_s: missing"}},
      {"simulate: {segments: [{duration_s: -1}]}", {"simulate.segments[0].duration_s: must be > 0"}},
      {"input: {max_errors: -1}", {"input.max_errors: must be >= 0"}},
  });
}

TEST(ConfigLoaderTest, GnssOutages) {
  const Options none = Load("gnss: {outages_s: [], periodic_outages_s: []}");
  EXPECT_TRUE(none.sensors.gnss.outages.empty());
  EXPECT_EQ(none.sensors.gnss.periodic_outages.duration, 0.0);
  EXPECT_EQ(Load("gnss: {periodic_outages_s: null}").sensors.gnss.periodic_outages.duration, 0.0);
  const Options o = Load("gnss:\n  outages_s: [[300, 60], [0, 0.5]]\n  periodic_outages_s: [250, 60, 180]\n");
  ASSERT_EQ(o.sensors.gnss.outages.size(), 2u);
  EXPECT_EQ(o.sensors.gnss.outages[0], std::make_pair(300.0, 60.0));
  EXPECT_EQ(o.sensors.gnss.outages[1], std::make_pair(0.0, 0.5));
  EXPECT_EQ(o.sensors.gnss.periodic_outages.first_start, 250.0);
  EXPECT_EQ(o.sensors.gnss.periodic_outages.duration, 60.0);
  EXPECT_EQ(o.sensors.gnss.periodic_outages.period, 180.0);
  const std::string yaml = OptionsToYaml(o);
  EXPECT_NE(yaml.find("  outages_s: [[300, 60], [0, 0.5]]\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("  periodic_outages_s: [250, 60, 180]\n"), std::string::npos) << yaml;
  EXPECT_NE(OptionsToYaml(Options()).find("  periodic_outages_s: []\n"), std::string::npos);
  ExpectErrors({
      {"gnss: {outages_s: [[10, 0]]}", {"gnss.outages_s[0][1]: must be > 0"}},
      {"gnss: {outages_s: [[-1, 5]]}", {"gnss.outages_s[0][0]: must be >= 0"}},
      {"gnss: {outages_s: [10, 5]}", {"gnss.outages_s[0]: expected [start_s, duration_s]"}},
      {"gnss: {periodic_outages_s: [60, 180]}", {"gnss.periodic_outages_s: expected a list of 3 numbers"}},
      {"gnss: {periodic_outages_s: [0, 0, 180]}", {"gnss.periodic_outages_s[1] (duration_s): must be > 0"}},
      {"gnss: {periodic_outages_s: [-5, 60, 180]}", {"gnss.periodic_outages_s[0] (first_start_s): must be >= 0"}},
      {"gnss: {periodic_outages_s: [0, 180, 60]}", {"gnss.periodic_outages_s: duration_s must be shorter"}},
      {"gnss: {outage_s: []}", {"gnss.outage_s: unknown key (did you mean gnss.outages_s?)"}},
  });
}

TEST(ConfigLoaderTest, DuplicateKeysAreErrors) {
  ExpectErrors({{"wheel:\n  radius_m: 0.3\n  radius_m: 0.2\n", {"wheel.radius_m: duplicate key", "(line 3)"}}});
}

TEST(ConfigLoaderTest, SyntaxErrorNamesFileAndLine) {
  const std::string message = ErrorOf("imu:\n  max_gap_s: 0.5\n  axes: [FLU\n");
  EXPECT_NE(message.find("test.yaml: YAML syntax error"), std::string::npos) << message;
  EXPECT_NE(message.find("line "), std::string::npos) << message;
  const std::string tabs = ErrorOf("imu:\n\tmax_gap_s: 0.5\n");
  EXPECT_NE(tabs.find("test.yaml: YAML syntax error"), std::string::npos) << tabs;
  EXPECT_NE(tabs.find("line 2"), std::string::npos) << tabs;
}

// Found by tests/fuzz/config_fuzzer: yaml-cpp quotes a raw control character in some messages, and keys may
// hold escaped ones; the message must stay one line.
TEST(ConfigLoaderTest, ErrorMessagesAreOneLineWhateverTheFileHolds) {
  for (const std::string& yaml : {std::string("imu:\n  axes: \"\\\n\"\n"), std::string("\"a\\nb\": 1\n"),
                                  std::string("input: \"\\\x01\"\n"), std::string("x: [\n")}) {
    const std::string e = ErrorOf(yaml);
    EXPECT_FALSE(e.empty()) << yaml;
    for (const char c : e) EXPECT_GE(static_cast<unsigned char>(c), 0x20u) << e;
  }
  EXPECT_NE(ErrorOf("\"a\\nb\": 1\n").find("a\\x0ab"), std::string::npos) << ErrorOf("\"a\\nb\": 1\n");
}

// Found by tests/fuzz/config_fuzzer: yaml-cpp 0.7's LoadAll never returns on a stray top-level ',' (it
// allocates until the machine runs out of memory). Refused quickly as a syntax error.
TEST(ConfigLoaderTest, StrayTopLevelCommaIsASyntaxErrorNotAHang) {
  for (const std::string& yaml : {std::string(","), std::string("  ,"), std::string("[1, 2]\n,\n"),
                                  std::string("imu:\n  max_gap_s: 0.2\n,")}) {
    const std::string e = ErrorOf(yaml);
    EXPECT_NE(e.find("test.yaml: YAML syntax error"), std::string::npos) << yaml << " -> " << e;
  }
  EXPECT_NE(ErrorOf("imu: {}\n---\ngnss: {}\n").find("more than one YAML document"), std::string::npos);
}

TEST(ConfigLoaderTest, ValueErrorsGiveTheLine) {
  EXPECT_NE(ErrorOf("imu:\n  max_gap_s: 0.5\n\nwheel:\n  radius_m: -1\n").find("(line 5)"), std::string::npos);
}

TEST(ConfigLoaderTest, UnreadableFileIsAConfigError) {
  try {
    LoadOptions("/nonexistent/dir/gins.yaml");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/gins.yaml: cannot open"), std::string::npos) << e.what();
  }
  const std::string dir = test::MakeTempDir("config_loader");
  EXPECT_THROW(LoadOptions(dir), ConfigError);
  test::WriteFile(dir + "/bad.yaml", "wheel: {radius_m: x}\n");
  try {
    LoadOptions(dir + "/bad.yaml");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/bad.yaml: wheel.radius_m"), std::string::npos) << e.what();
  }
}

// ---- Writing ---------------------------------------------------------------------------------------------

TEST(ConfigLoaderTest, NonDefaultOptionsChangeEveryField) {
  const Comparison c = Compare(NonDefaultOptions(), Options());
  EXPECT_EQ(static_cast<int>(c.differing.size()), c.fields);
}

TEST(ConfigLoaderTest, RoundTripIsExact) {
  std::vector<std::pair<std::string, Options>> cases = {
      {"defaults", Options()},
      {"non-default", NonDefaultOptions()},
      {"wvu_rover.yaml", LoadOptions(kConfigDir + "wvu_rover.yaml")},
      {"sim_sample.yaml", LoadOptions(kConfigDir + "sim_sample.yaml")},
      {"rtkx_walk_raw.yaml", LoadOptions(kConfigDir + "rtkx_walk_raw.yaml")},
  };
  for (const auto& [name, o] : cases) {
    SCOPED_TRACE(name);
    const std::string yaml = OptionsToYaml(o);
    const Options back = LoadOptionsFromString(yaml, name + " (echoed)");
    ExpectSameOptions(back, o);
    EXPECT_EQ(OptionsToYaml(back), yaml);
  }
}

TEST(ConfigLoaderTest, EchoIsWrittenInUsersUnitsWithShortNumbers) {
  const std::string yaml = OptionsToYaml(Options());
  for (const char* line :
       {"  gyro_noise_deg_sqrt_h: 0.8\n", "  gyro_bias_rw_deg_h_sqrt_h: 60\n", "  acc_bias_rw_m_s2_sqrt_h: 0.01\n",
        "  mount_yaw_deg: 12.06\n", "  lever_arm_m: [-0.17, -0.2, 0]\n", "  axes: FLU\n", "  initial_heading_deg: 90\n",
        "  on_error: skip\n", "  model: normal\n", "  origin: null"}) {
    EXPECT_NE(yaml.find(line), std::string::npos) << "no '" << line << "' in\n" << yaml;
  }
}

TEST(ConfigLoaderTest, EchoWritesSegmentsOutagesAndMatrices) {
  const std::string yaml = OptionsToYaml(NonDefaultOptions());
  EXPECT_NE(yaml.find("- {duration_s: 10, accel_m_s2: 1, yaw_rate_deg_s: 9, grade_deg: 3, reverse: false}"),
            std::string::npos)
      << yaml;
  EXPECT_NE(yaml.find("gnss_outages_s: [[40, 15], [100.5, 2]]"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("axes: [0, 0, 1, 1, 0, 0, 0, 1, 0]"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("initial_heading_deg: 30"), std::string::npos) << yaml;
}

// gnss.time_offset_s: a number (held) or `estimate` (a state in the ESKF); the writer writes back what was read.
TEST(ConfigLoaderTest, GnssTimeOffsetIsANumberOrEstimate) {
  const Options held = Load("gnss: {time_offset_s: 0.12}");
  EXPECT_EQ(held.sensors.gnss.time_offset, 0.12);
  EXPECT_FALSE(held.sensors.gnss.estimate_time_offset);
  const Options estimated = Load("gnss: {time_offset_s: estimate, time_offset_sigma_s: 0.2}");
  EXPECT_TRUE(estimated.sensors.gnss.estimate_time_offset);
  EXPECT_EQ(estimated.sensors.gnss.time_offset, 0.0);
  EXPECT_EQ(estimated.sensors.gnss.time_offset_sigma, 0.2);
  EXPECT_NE(OptionsToYaml(estimated).find("  time_offset_s: estimate\n"), std::string::npos);
  EXPECT_TRUE(Load(OptionsToYaml(estimated)).sensors.gnss.estimate_time_offset);
  EXPECT_NE(OptionsToYaml(held).find("  time_offset_s: 0.12\n"), std::string::npos);
  ExpectErrors({
      {"gnss: {time_offset_s: estimated}", {"gnss.time_offset_s: expected a number or 'estimate'", "estimated"}},
      {"gnss: {time_offset_s: 7}", {"gnss.time_offset_s: must be within [-5, 5]"}},
      {"gnss: {time_offset_s: [0.1]}", {"gnss.time_offset_s: expected a number or 'estimate'"}},
  });
}

}  // namespace
}  // namespace gins
