// The simulator's field-log set-ups: GNSS velocity (GVEL), reversing, a log that starts while driving and
// time-correlated GNSS position noise, and their config keys.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "config/config_loader.h"
#include "core/sim/simulator.h"
#include "core/so3.h"
#include "core/wheel_model.h"
#include "sim_test_util.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

using test::FarDrive;
using test::NoiseFreeSim;
using test::OfType;
using test::RunAll;

// 60 s (simulator_test.cc's drive): standstill, accelerate, climbing left turn, level right turn,
// descending left turn while braking, accelerate, brake to a stop at ~57 s.
SimOptions Drive() {
  SimOptions sim;
  sim.seed = 7;
  sim.initial_yaw = 0.3;
  sim.segments = {{2.0, 0.0, 0.0, 0.0},          {6.0, 1.5, 0.0, 0.0},
                  {10.0, 0.0, 0.15, 4 * kDegToRad}, {8.0, 0.2, -0.2, 0.0},
                  {10.0, -0.5, 0.1, -3 * kDegToRad}, {14.0, 0.3, 0.0, 0.0},
                  {10.0, -1.5, 0.0, 0.0}};
  return sim;
}

bool SameImu(const ImuSample& a, const ImuSample& b) { return a.t == b.t && a.gyro == b.gyro && a.acc == b.acc; }

bool SameFields(const ImuSample& a, const ImuSample& b) { return SameImu(a, b); }
bool SameFields(const WheelRecord& a, const WheelRecord& b) {
  return a.left_pulses == b.left_pulses && a.right_pulses == b.right_pulses;
}
bool SameFields(const GnssRecord& a, const GnssRecord& b) {
  return a.lat_deg == b.lat_deg && a.lon_deg == b.lon_deg && a.alt_m == b.alt_m && a.heading_deg == b.heading_deg &&
         a.heading_valid == b.heading_valid;
}
bool SameFields(const GnssVelocityRecord& a, const GnssVelocityRecord& b) { return a.v_enu == b.v_enu; }
template <typename R>  // a measurement module's record: its numbers
bool SameFields(const R& a, const R& b) {
  double va[RecordTraits<R>::kInfo.max_fields], vb[RecordTraits<R>::kInfo.max_fields];
  const size_t n = R::Values(a, va);
  return n == R::Values(b, vb) && std::equal(va, va + n, vb);
}

// Bit for bit, whatever the type.
bool SameRecord(const SimRecord& a, const SimRecord& b) {
  return a.type_index() == b.type_index() && a.t() == b.t() && std::visit([&b](const auto& m) {
           return SameFields(m, std::get<std::decay_t<decltype(m)>>(b.data));
         }, a.data);
}

template <typename R>
std::vector<SimRecord> Without(const std::vector<SimRecord>& all) {
  std::vector<SimRecord> out;
  for (const SimRecord& r : all) {
    if (!r.is<R>()) out.push_back(r);
  }
  return out;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> Fields(const std::string& line, char sep = ' ') {
  std::vector<std::string> f;
  std::istringstream in(line);
  for (std::string s; std::getline(in, s, sep);) {
    if (!s.empty()) f.push_back(s);
  }
  return f;
}

// The antenna's velocity in w by central differences of the truth's antenna position.
Vec3 AntennaVelocityW(const TruthTrajectory& truth, double s, const Vec3& lever_b) {
  const double h = 1e-4;
  const TruthState m = truth.AtElapsed(s - h), p = truth.AtElapsed(s + h);
  return ((p.p_wb + p.q_wb * lever_b) - (m.p_wb + m.q_wb * lever_b)) / (2.0 * h);
}

// ---------------------------------------------------------------------------------------------------------
// GNSS velocity

TEST(SimGvel, EveryFixHasAVelocityRecordRightAfterIt) {
  SimOptions options = Drive();
  options.gnss_rate = 10.0;
  options.gnss_outages = {{10.0, 5.0}};
  options.gnss_velocity_sigma = Vec3(0.03, 0.04, 0.08);
  const std::vector<SimRecord> all = RunAll(options);
  size_t gnss = 0, gnss_velocity = 0;
  for (size_t i = 0; i < all.size(); ++i) {
    if (all[i].is<GnssRecord>()) {
      ++gnss;
      ASSERT_LT(i + 1, all.size());
      EXPECT_TRUE(all[i + 1].is<GnssVelocityRecord>()) << all[i].t();
      EXPECT_EQ(all[i + 1].t(), all[i].t());
    } else if (all[i].is<GnssVelocityRecord>()) {
      ++gnss_velocity;
      ASSERT_GT(i, 0u);
      EXPECT_TRUE(all[i - 1].is<GnssRecord>());
      EXPECT_TRUE(all[i].get<GnssVelocityRecord>().has_sigma);
      EXPECT_EQ(all[i].get<GnssVelocityRecord>().sigma_enu, options.gnss_velocity_sigma);
      const double s = all[i].t() - options.start_time;
      EXPECT_FALSE(s > 10.0 - 1e-4 && s < 15.0 - 1e-4) << s;  // the outage holds for GVEL too
    }
  }
  EXPECT_EQ(gnss, 601u - 50u);
  EXPECT_EQ(gnss_velocity, gnss);

  // σ = 0: no GVEL, and every other record unchanged (GVEL draws from its own stream).
  options.gnss_velocity_sigma.setZero();
  const std::vector<SimRecord> none = RunAll(options);
  EXPECT_TRUE(OfType<GnssVelocityRecord>(none).empty());
  const std::vector<SimRecord> rest = Without<GnssVelocityRecord>(all);
  ASSERT_EQ(rest.size(), none.size());
  for (size_t i = 0; i < rest.size(); ++i) ASSERT_TRUE(SameRecord(rest[i], none[i])) << i;
}

// Noise-free (σ tiny), a GVEL record is the antenna velocity v_w + R_wb·(ω_b × lever_b): checked against
// differences of the antenna position, in w (flat) and in the local ENU frame at the antenna (rotating,
// ~9 km from the origin, where the two differ by 1.5 mrad, 40 mm/s at 27 m/s).
TEST(SimGvel, NoiseFreeRecordsAreTheAntennaVelocity) {
  for (bool rotating : {false, true}) {
    SCOPED_TRACE(rotating ? "rotating" : "flat");
    SimOptions options = NoiseFreeSim(rotating ? FarDrive() : Drive());
    options.earth_rotation = rotating;
    options.lever_b = Vec3(-0.9, 0.6, 1.2);
    options.gnss_rate = 5.0;
    options.imu_rate = 1.0;
    options.gnss_velocity_sigma = Vec3::Constant(1e-12);
    Simulator sim(options);
    const LocalEnuFrame& frame = sim.truth().frame();
    double max_err = 0.0, max_rotation_effect = 0.0;
    int checked = 0;
    SimRecord r;
    while (sim.Next(&r)) {
      if (!r.is<GnssVelocityRecord>()) continue;
      const double s = r.get<GnssVelocityRecord>().t - options.start_time;
      if (s < 1e-3 || s > sim.truth().duration() - 1e-3) continue;  // differences need both sides
      const Vec3 v_ant_w = AntennaVelocityW(sim.truth(), s, options.lever_b);
      const TruthState x = sim.truth().AtElapsed(s);
      const Vec3 p_ant_w = x.p_wb + x.q_wb * options.lever_b;
      const Mat3 R_w_l = rotating ? frame.RotationFromLocalEnu(frame.ToGeodetic(p_ant_w)) : Mat3::Identity();
      max_err = std::max(max_err, (r.get<GnssVelocityRecord>().v_enu - R_w_l.transpose() * v_ant_w).norm());
      max_rotation_effect = std::max(max_rotation_effect, (r.get<GnssVelocityRecord>().v_enu - v_ant_w).norm());
      ++checked;
    }
    EXPECT_GT(checked, 290);
    EXPECT_LT(max_err, 1e-6);
    if (rotating) {
      EXPECT_GT(max_rotation_effect, 0.03);
    }
  }
}

TEST(SimGvel, NoiseMatchesSigma) {
  SimOptions options = Drive();
  options.gnss_rate = 20.0;
  options.imu_rate = 1.0;
  options.wheel_rate = 0.0;
  options.gnss_velocity_sigma = Vec3(0.02, 0.05, 0.1);
  Simulator sim(options);
  Vec3 sum_sq = Vec3::Zero();
  int n = 0;
  SimRecord r;
  while (sim.Next(&r)) {
    if (!r.is<GnssVelocityRecord>()) continue;
    const TruthState x = sim.truth().AtElapsed(static_cast<double>(n) / options.gnss_rate);
    const Vec3 v_ant_w = x.v_w + x.q_wb * x.omega_b.cross(options.lever_b);
    sum_sq += (r.get<GnssVelocityRecord>().v_enu - v_ant_w).cwiseAbs2();
    ++n;
  }
  ASSERT_EQ(n, 1201);
  const Vec3 rms = (sum_sq / n).cwiseSqrt();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(rms[i] / options.gnss_velocity_sigma[i], 1.0, 0.1);  // ±2 % 1-σ
}

TEST(SimGvel, WrittenAfterItsFixWithSigmaColumns) {
  SimOptions options = Drive();
  options.segments.resize(3);  // 18 s
  options.gnss_rate = 2.0;
  options.gnss_velocity_sigma = Vec3(0.05, 0.05, 0.1);
  const std::string dir = test::MakeTempDir("sim_gvel");
  const SimulationResult result = Simulate(options, dir);
  EXPECT_EQ(CountOf<GnssVelocityRecord>(result.records), 37u);
  EXPECT_EQ(CountOf<GnssRecord>(result.records), 37u);
  const std::vector<std::string> log = Lines(test::ReadFile(dir + "/log.txt"));
  EXPECT_NE(log.at(1).find("| GVEL t ve vn vu se sn su"), std::string::npos) << log[1];
  const std::vector<SimRecord> gnss_velocity = OfType<GnssVelocityRecord>(RunAll(options));
  size_t n = 0;
  for (size_t i = 0; i < log.size(); ++i) {
    const std::vector<std::string> f = Fields(log[i]);
    if (f.at(0) != "GVEL") continue;
    ASSERT_EQ(f.size(), 8u) << log[i];
    EXPECT_EQ(Fields(log[i - 1]).at(0), "GNSS");
    EXPECT_EQ(Fields(log[i - 1]).at(1), f[1]);
    const GnssVelocityRecord& g = gnss_velocity.at(n++).get<GnssVelocityRecord>();
    EXPECT_NEAR(std::stod(f[1]), g.t, 1e-6);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(std::stod(f[2 + k]), g.v_enu[k], 5.001e-5);
      EXPECT_EQ(std::stod(f[5 + k]), options.gnss_velocity_sigma[k]);
    }
  }
  EXPECT_EQ(n, gnss_velocity.size());
}

// ---------------------------------------------------------------------------------------------------------
// Reversing

// 42 s: standstill, forward to 8.25 m/s, brake to a stop (~14.5 s), stand, back up in a climbing left
// curve to 6 m/s, brake to a stop (~29.9 s), stand, drive off forward.
SimOptions ReverseDrive() {
  SimOptions sim = NoiseFreeSim(Drive());
  sim.segments = {{2.0, 0.0, 0.0, 0.0},  {6.0, 1.5, 0.0, 0.0},          {8.0, -1.5, 0.0, 0.0},
                  {3.0, 0.0, 0.0, 0.0},  {8.0, 0.8, 0.1, 0.03, true},   {8.0, -1.0, 0.0, 0.0, true},
                  {2.0, 0.0, 0.0, 0.0, true}, {5.0, 1.0, 0.0, 0.0}};
  return sim;
}

TEST(SimReverse, BacksUpFacingForwardWithoutSideSlip) {
  const TruthTrajectory truth(ReverseDrive());
  EXPECT_DOUBLE_EQ(truth.duration(), 42.0);
  int backing = 0, checked = 0;
  const double h = 1e-4;
  for (double s = 0.013; s < truth.duration() - h; s += 0.0731) {
    const TruthState m = truth.AtElapsed(s - h), x = truth.AtElapsed(s), p = truth.AtElapsed(s + h);
    ASSERT_GE(x.speed, 0.0);
    const Vec3 v_b = x.q_wb.conjugate() * x.v_w;
    EXPECT_LT(v_b.tail<2>().norm(), 1e-12) << s;  // no side slip, forwards or backwards
    EXPECT_NEAR(v_b.x(), x.reverse ? -x.speed : x.speed, 1e-12) << s;
    EXPECT_EQ(x.reverse, s >= 19.0 && s < 37.0) << s;
    if (x.reverse && x.speed > 0.5) {
      // Backing up in a left curve: the body yaws left while the position moves against the nose.
      EXPECT_LT((p.p_wb - m.p_wb).dot(x.q_wb * Vec3::UnitX()), 0.0) << s;
      ++backing;
    }
    EXPECT_LT(((p.p_wb - m.p_wb) / (2 * h) - x.v_w).norm(), 1e-7) << s;
    EXPECT_LT((LogQuat<double>(m.q_wb.conjugate() * p.q_wb) / (2 * h) - x.omega_b).norm(), 1e-7) << s;
    if (m.speed == 0.0 || p.speed == 0.0) continue;  // the stops are the kinks in a_w
    EXPECT_LT(((p.v_w - m.v_w) / (2 * h) - x.a_w).norm(), 1e-6) << s;
    ++checked;
  }
  EXPECT_GT(backing, 120);
  EXPECT_GT(checked, 400);
}

TEST(SimReverse, WheelPulsesAreNegativeWhenBackingUp) {
  const SimOptions options = ReverseDrive();
  const std::vector<SimRecord> wheel = OfType<WheelRecord>(RunAll(options));
  const TruthTrajectory truth(options);
  const double dt = 1.0 / options.wheel_rate;
  const double pulse_speed = WheelSpeedFromPulses(1.0, options.wheel_radius, options.pulses_per_rev, dt);
  int negative = 0;
  for (const SimRecord& r : wheel) {
    const WheelRecord& wheel_record = r.get<WheelRecord>();
    const double s1 = wheel_record.t - options.start_time;
    const Vec2 mean = truth.IntegrateSpeedAndYawRate(s1 - dt, s1) / dt;  // signed
    const double left = WheelSpeedFromPulses(wheel_record.left_pulses, options.wheel_radius, options.pulses_per_rev, dt);
    const double right = WheelSpeedFromPulses(wheel_record.right_pulses, options.wheel_radius, options.pulses_per_rev, dt);
    EXPECT_NEAR(0.5 * (left + right) / options.wheel_scale, mean.x(), pulse_speed / options.wheel_scale + 1e-9);
    if (truth.AtElapsed(s1).reverse && mean.x() < -0.5) {
      EXPECT_LT(wheel_record.left_pulses, 0.0) << s1;
      EXPECT_LT(wheel_record.right_pulses, 0.0) << s1;
      ++negative;
    }
  }
  EXPECT_GT(negative, 100);
}

std::string InvalidArgument(const SimOptions& options) {
  try {
    Simulator sim(options);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(SimReverse, GearChangesOnlyAtAStandstill) {
  SimOptions sim = NoiseFreeSim(Drive());
  sim.segments = {{2.0, 0.0, 0.0, 0.0}, {6.0, 1.5, 0.0, 0.0}, {5.0, 0.0, 0.0, 0.0, true}};
  std::string what = InvalidArgument(sim);
  EXPECT_NE(what.find("simulate: segments[2] (reverse: true) changes gear at 8.000 s while moving at 8.250 m/s"),
            std::string::npos)
      << what;
  EXPECT_NE(what.find("standstill"), std::string::npos) << what;

  // A zero-length segment does not exist, gear included.
  sim.segments = {{2.0, 0.0, 0.0, 0.0}, {6.0, 1.5, 0.0, 0.0}, {0.0, 0.0, 0.0, 0.0, true}, {3.0, 0.0, 0.0, 0.0}};
  EXPECT_EQ(InvalidArgument(sim), "");

  // Lap 2 starts in reverse while lap 1 ends driving forward.
  sim.segments = {{5.0, 1.0, 0.0, 0.0, true}, {10.0, -1.0, 0.0, 0.0, true}, {3.0, 0.0, 0.0, 0.0, true},
                  {4.0, 1.0, 0.0, 0.0}};
  EXPECT_EQ(InvalidArgument(sim), "");
  sim.repeat = 2;
  what = InvalidArgument(sim);
  EXPECT_NE(what.find("segments[0] (lap 2) (reverse: true) changes gear at 22.000 s"), std::string::npos) << what;
}

// As other errors found across segments, a bad change of gear surfaces when `gins simulate` runs the
// loaded options: the loader checks each key, Simulate the drive, before any file is written.
TEST(SimReverse, BadGearChangeFromConfigIsReportedAndWritesNothing) {
  const Options o = LoadOptionsFromString(
      "simulate:\n"
      "  segments:\n"
      "    - {duration_s: 2}\n"
      "    - {duration_s: 6, accel_m_s2: 1.5}\n"
      "    - {duration_s: 5, accel_m_s2: -0.5, reverse: true}\n",
      "test.yaml");
  ASSERT_EQ(o.simulate.segments.size(), 3u);
  EXPECT_FALSE(o.simulate.segments[1].reverse);
  EXPECT_TRUE(o.simulate.segments[2].reverse);
  const std::string dir = test::MakeTempDir("sim_gear") + "/out";
  try {
    Simulate(o.simulate, dir);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("simulate: segments[2] (reverse: true) changes gear"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir));
}

// ---------------------------------------------------------------------------------------------------------
// A log that starts while driving

TEST(SimLogStart, RecordsStartAtTheCutAndAreThoseOfTheWholeDrive) {
  SimOptions options = Drive();
  options.gnss_rate = 5.0;
  options.gnss_velocity_sigma = Vec3(0.05, 0.05, 0.1);
  options.gnss_noise_correlation = 10.0;
  const std::vector<SimRecord> whole = RunAll(options);
  options.log_start = 12.34;
  const std::vector<SimRecord> cut = RunAll(options);
  const double t_cut = options.start_time + 12.34;
  ASSERT_FALSE(cut.empty());
  EXPECT_TRUE(cut.front().is<ImuSample>());
  EXPECT_NEAR(cut.front().t(), t_cut, 1e-6);
  EXPECT_GT(cut.front().truth.v_w.norm(), 5.0);  // driving
  EXPECT_NEAR(OfType<GnssRecord>(cut).front().t(), options.start_time + 12.4, 1e-6);
  EXPECT_NEAR(OfType<GnssVelocityRecord>(cut).front().t(), options.start_time + 12.4, 1e-6);
  // Pulses over (12.3, 12.4] straddle the cut: the first encoder record counts over (12.4, 12.5].
  EXPECT_NEAR(OfType<WheelRecord>(cut).front().t(), options.start_time + 12.5, 1e-6);

  // The same records, bit for bit, as the whole drive's from the cut on (bias walks, pulse remainders and
  // the correlated GNSS error all ran before it).
  std::vector<SimRecord> expected;
  for (const SimRecord& r : whole) {
    const bool odom_straddles = r.is<WheelRecord>() && r.t() < t_cut + 0.1 - 1e-6;
    if (r.t() >= t_cut - 1e-6 && !odom_straddles) expected.push_back(r);
  }
  ASSERT_EQ(cut.size(), expected.size());
  for (size_t i = 0; i < cut.size(); ++i) {
    ASSERT_TRUE(SameRecord(cut[i], expected[i])) << i;
    EXPECT_EQ(cut[i].truth.p_wb, expected[i].truth.p_wb);
    EXPECT_EQ(cut[i].truth.bg, expected[i].truth.bg);
  }

  // In the files: the log's first record and the truth's first row at the cut, time stamps absolute.
  options.segments.resize(4);  // 26 s
  const std::string dir = test::MakeTempDir("sim_log_start");
  const SimulationResult result = Simulate(options, dir);
  EXPECT_EQ(CountOf<ImuSample>(result.records), 2600u - 1234u + 1u);
  EXPECT_DOUBLE_EQ(result.duration, 26.0);
  const std::vector<std::string> log = Lines(test::ReadFile(dir + "/log.txt"));
  EXPECT_NE(log.at(0).find(" log_start=12.34"), std::string::npos) << log[0];
  EXPECT_EQ(log.at(2).rfind("IMU 1700000012.340000 ", 0), 0u) << log[2];
  const std::vector<std::string> truth = Lines(test::ReadFile(dir + "/truth.csv"));
  EXPECT_EQ(truth.size(), 1u + CountOf<ImuSample>(result.records));
  EXPECT_EQ(truth.at(1).rfind("1700000012.340000,", 0), 0u) << truth[1];
}

TEST(SimLogStart, MustBeWithinTheDrive) {
  SimOptions options = Drive();
  options.log_start = 60.0;
  EXPECT_NE(InvalidArgument(options).find("log_start"), std::string::npos);
  options.log_start = -1.0;
  EXPECT_NE(InvalidArgument(options).find("log_start"), std::string::npos);
  options.log_start = 59.99;
  EXPECT_EQ(OfType<ImuSample>(RunAll(options)).size(), 2u);
}

// ---------------------------------------------------------------------------------------------------------
// Correlated GNSS position noise

// The fixes' position errors (fix − true antenna position) in w.
std::vector<Vec3> GnssErrors(const SimOptions& options) {
  const LocalEnuFrame frame(options.origin);
  std::vector<Vec3> e;
  for (const SimRecord& r : OfType<GnssRecord>(RunAll(options))) {
    const GnssRecord& fix = r.get<GnssRecord>();
    const NavState& x = r.truth;
    e.push_back(frame.ToEnu({fix.lat_deg, fix.lon_deg, fix.alt_m}) - (x.p_wb + x.q_wb * options.lever_b));
  }
  return e;
}

// An hour parked with 5 Hz single-point-like fixes and τ = 2 s: per axis the error's standard deviation is
// σ and its lag-1 autocorrelation exp(−0.2/2) = 0.905 (18001 fixes: 1-σ sampling errors 1.7 % and 0.003;
// measured 1.025, 1.026, 1.010 and 0.908, 0.909, 0.907); white (τ = 0) the autocorrelation is ~0 (1-σ
// 0.007; measured −0.001, 0.006, 0.004).
TEST(SimGnssCorrelation, GaussMarkovStatistics) {
  SimOptions options;
  options.seed = 3;
  options.segments = {{3600.0, 0.0, 0.0, 0.0}};
  options.imu_rate = 0.1;
  options.wheel_rate = 0.0;
  options.gnss_rate = 5.0;
  options.gnss_sigma_enu = Vec3(1.0, 1.5, 2.5);
  for (double tau : {2.0, 0.0}) {
    SCOPED_TRACE(tau);
    options.gnss_noise_correlation = tau;
    const std::vector<Vec3> e = GnssErrors(options);
    ASSERT_EQ(e.size(), 18001u);
    const double rho = tau > 0.0 ? std::exp(-0.2 / tau) : 0.0;
    for (int axis = 0; axis < 3; ++axis) {
      double sum_sq = 0.0, sum_lag1 = 0.0, sum_lag5 = 0.0;
      for (size_t k = 0; k < e.size(); ++k) {
        sum_sq += e[k][axis] * e[k][axis];
        if (k >= 1) sum_lag1 += e[k][axis] * e[k - 1][axis];
        if (k >= 5) sum_lag5 += e[k][axis] * e[k - 5][axis];
      }
      EXPECT_NEAR(std::sqrt(sum_sq / e.size()) / options.gnss_sigma_enu[axis], 1.0, 0.07) << axis;
      EXPECT_NEAR(sum_lag1 / sum_sq, rho, 0.015) << axis;
      EXPECT_NEAR(sum_lag5 / sum_sq, std::pow(rho, 5), 0.04) << axis;
    }
  }
}

// The correlated errors are made of the white run's draws: e_k = ρ·e_{k−1} + √(1−ρ²)·w_k with w the white
// run's errors. Nothing else changes, and τ → 0 is the white noise bit for bit.
TEST(SimGnssCorrelation, MadeOfTheWhiteNoiseDraws) {
  SimOptions white = Drive();
  white.gnss_rate = 10.0;
  white.gnss_sigma_enu = Vec3(0.5, 0.7, 1.2);
  SimOptions correlated = white;
  correlated.gnss_noise_correlation = 3.0;
  const std::vector<Vec3> w = GnssErrors(white), e = GnssErrors(correlated);
  ASSERT_EQ(w.size(), 601u);
  ASSERT_EQ(e.size(), w.size());
  const double rho = std::exp(-0.1 / 3.0);
  Vec3 expected = w[0];
  for (size_t k = 0; k < e.size(); ++k) {
    if (k > 0) expected = rho * expected + std::sqrt(1.0 - rho * rho) * w[k];
    ASSERT_LT((e[k] - expected).norm(), 1e-6) << k;
  }
  const std::vector<SimRecord> a = RunAll(white), b = RunAll(correlated);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].is<GnssRecord>()) {
      EXPECT_EQ(a[i].get<GnssRecord>().heading_deg, b[i].get<GnssRecord>().heading_deg);
    } else {
      ASSERT_TRUE(SameRecord(a[i], b[i])) << i;
    }
  }
  SimOptions tiny = white;
  tiny.gnss_noise_correlation = 1e-300;  // ρ underflows to 0
  const std::vector<SimRecord> c = RunAll(tiny);
  ASSERT_EQ(c.size(), a.size());
  for (size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(SameRecord(a[i], c[i])) << i;
}

// ---------------------------------------------------------------------------------------------------------
// Config keys

TEST(SimConfig, NewKeysLoadValidateAndEcho) {
  const std::string yaml =
      "simulate:\n"
      "  earth_rotation: true\n"
      "  gnss_velocity_sigma_m_s: [0.05, 0.06, 0.1]\n"
      "  gnss_noise_correlation_s: 30\n"
      "  log_start_s: 12.5\n"
      "  segments:\n"
      "    - {duration_s: 5}\n"
      "    - {duration_s: 4, accel_m_s2: 0.5, reverse: true}\n";
  const Options o = LoadOptionsFromString(yaml, "test.yaml");
  const SimOptions& s = o.simulate;
  EXPECT_TRUE(s.earth_rotation);
  EXPECT_EQ(s.gnss_velocity_sigma, Vec3(0.05, 0.06, 0.1));
  EXPECT_EQ(s.gnss_noise_correlation, 30.0);
  EXPECT_EQ(s.log_start, 12.5);
  ASSERT_EQ(s.segments.size(), 2u);
  EXPECT_TRUE(s.segments[1].reverse);
  const std::string echo = OptionsToYaml(o);
  for (const char* line : {"  earth_rotation: true\n", "  gnss_velocity_sigma_m_s: [0.05, 0.06, 0.1]\n",
                           "  gnss_noise_correlation_s: 30\n", "  log_start_s: 12.5\n",
                           "    - {duration_s: 4, accel_m_s2: 0.5, yaw_rate_deg_s: 0, grade_deg: 0, reverse: true}\n"}) {
    EXPECT_NE(echo.find(line), std::string::npos) << "no '" << line << "' in\n" << echo;
  }
  const Options back = LoadOptionsFromString(echo, "echo.yaml");
  EXPECT_EQ(OptionsToYaml(back), echo);

  // Defaults: the rotating Earth, white noise, the whole drive, no GNSS velocity.
  const SimOptions d = LoadOptionsFromString("simulate: {}\n", "test.yaml").simulate;
  EXPECT_TRUE(d.earth_rotation);
  EXPECT_TRUE(d.gnss_velocity_sigma.isZero());
  EXPECT_EQ(d.gnss_noise_correlation, 0.0);
  EXPECT_EQ(d.log_start, 0.0);

  for (const char* bad : {"simulate: {gnss_velocity_sigma_m_s: [0.1, -0.1, 0.1]}\n",
                          "simulate: {gnss_noise_correlation_s: -1}\n", "simulate: {log_start_s: -0.5}\n",
                          "simulate: {earth_rotation: 1.5}\n", "simulate: {segments: [{duration_s: 1, reverse: 2}]}\n"}) {
    EXPECT_THROW(LoadOptionsFromString(bad, "test.yaml"), ConfigError) << bad;
  }
}

}  // namespace
}  // namespace gins
