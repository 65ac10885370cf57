// The byte format of the stream fuzzer (stream_fuzzer.cc): bytes -> run options and a sequence of log records
// that the log reader could have produced (every value inside log_limits, time non-decreasing, no two records
// of one type on one time stamp). Shared by the fuzzer, its seed maker (make_stream_seeds.cc) and the corpus
// replay test (tests/solver/stream_corpus_test.cc). Missing bytes read as zero, so every input decodes.
//
// Header, 4 bytes:
//   h0 bits: 0 wheel.enabled, 1 gnss.use_heading, 2 init.wait_for_heading, 3 gnss.use_velocity,
//            4 standstill.enabled, 5 vehicle.nonholonomic, 6 eskf.estimate_gravity, 7 watchdog.enabled
//   h1 bits: 0-1 smoother.window_size − 2, 2-3 smoother.max_iterations − 1, 4 dense_schur, 5 init.static_
//            duration_s 0.5 (else 2), 6 gnss.origin at the base point (else the first fix), 7 edge options
//            (min_keyframe_interval 0, max_keyframe_interval 0.2 s, imu.max_gap 0.05 s, watchdog 2 s / 5 m)
//   h2 bits: 0-3 start time (kStartTimes), 4-5 IMU period (kImuDt[0..3]), 6-7 imu.axes (FLU, FRD, RFU, FLU)
//   h3 bits: 0-2 base point (kBases), the origin of relative GNSS positions and of the vehicle
// Then operations until the bytes end. An op byte is (parameter << 4) | opcode:
//   0 IMU      dt code; 6 × int16: gyro, acc (cubic map onto ±35 rad/s, ±200 m/s²)
//   1 IMU_D    dt code; 6 × int8: the previous IMU sample plus steps of 1e-4 rad/s, 2e-3 m/s²
//   2 ODOM     dt code; 2 × int24: left, right pulses
//   3 GNSS     dt code; flags (0 heading valid, 1 σ, 2 absolute, 3 metres); 3 × int32 position (relative:
//              ENU offset from the base in mm or m; absolute: lat, lon scaled to ±90°, ±180°, alt in 0.1 mm);
//              uint16 heading (360·x/65536 deg); with σ 3 × uint8 (1e-4·10^(x/32) m)
//   4 GVEL     dt code; flags (0 σ); 3 × int16 velocity (cubic map onto ±1000 m/s); with σ 3 × uint8
//   5 STAND    sensors; uint8 n: 4(n+1) IMU samples of the vehicle at rest
//   6 DRIVE    sensors; uint8 n, int8 acceleration (0.05 m/s²), int8 yaw rate (0.005 rad/s): 4(n+1) samples
//   7 GAP      kGaps[parameter] seconds with no record
//   8 BURST    the next parameter + 1 records share one time stamp
//   9 RATE     IMU period kImuDt[parameter & 7]
//  10 JITTER   time-stamp jitter of the vehicle's IMU, ± kJitters[parameter & 7]
//  11 NOISE    IMU noise level kNoise*[parameter & 3]
//  12 JUMP     the vehicle's fixes move by kJumps[parameter & 7] m (0: back) in direction uint8·2π/256
//  13 WHEELS   wheel fault (parameter & 3): none, silent, zero pulses, twice the pulses
//  14 HEADING  heading fault (parameter & 3): none, frozen, invalid, off by 180°
//  15 MASK     the vehicle's sensors dropped: bit 0 IMU, 1 ODOM, 2 GNSS, 3 GVEL
// "dt code" is the parameter: the record comes kSteps[parameter] s after the newest one. "sensors" bits of
// the vehicle ops: 0 ODOM every 0.1 s, 1 GNSS every 1 s, 2 with a valid heading, 3 GVEL with each fix.
// The vehicle (STAND, DRIVE) is a level car: its IMU, wheels and fixes agree with one another.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <memory>
#include <string>
#include <variant>

#include "config/options.h"
#include "core/geodesy.h"
#include "core/io/log_reader.h"
#include "core/so3.h"

namespace gins::fuzz {

enum Op : uint8_t {
  kOpImu = 0, kOpImuDelta, kOpOdom, kOpGnss, kOpGvel, kOpStand, kOpDrive, kOpGap,
  kOpBurst, kOpRate, kOpJitter, kOpNoise, kOpJump, kOpWheels, kOpHeading, kOpMask
};

inline constexpr std::array<double, 16> kSteps = {0.0, 1e-6, 1e-3, 0.0025, 0.005, 0.01, 0.02, 0.05,
                                                  0.1, 0.2,  0.5,  1.0,    2.0,   5.0,  30.0, 61.0};
inline constexpr std::array<double, 16> kGaps = {0.05, 0.1,  0.3,  0.5,   0.6,    1.0, 1.5, 2.0,
                                                 3.5,  10.0, 30.0, 61.0, 600.0, 3600.0, 1e5, 1e7};
inline constexpr std::array<double, 8> kImuDt = {0.01, 0.005, 0.02, 0.0025, 0.1, 0.3, 0.001, 0.6};
inline constexpr std::array<double, 8> kJitters = {0.0, 1e-4, 1e-3, 5e-3, 0.01, 0.02, 0.05, 0.2};
inline constexpr std::array<double, 4> kNoiseGyro = {1e-3, 0.0, 1e-2, 0.3};  // rad/s, uniform ±
inline constexpr std::array<double, 4> kNoiseAcc = {1e-2, 0.0, 0.1, 3.0};    // m/s²
inline constexpr std::array<double, 8> kJumps = {0.0, 1.0, 10.0, 100.0, 1e3, 1e4, 1e5, 1e6};
inline constexpr std::array<double, 16> kStartTimes = {1.7e9, 1e-3, 1.0,  345600.0, 604799.5, 1e6, 1e9, 1e12,
                                                       4.2e9, 0.5,  100.0, 1e5,     86400.0,  3e7, 2e9, 1e10};
inline constexpr std::array<GeodeticPoint, 8> kBases = {{{31.508183, 120.401989, 12.0},
                                                         {0.0, 0.0, 0.0},
                                                         {89.9999, 0.0, 0.0},
                                                         {90.0, 0.0, 0.0},
                                                         {-90.0, 180.0, 0.0},
                                                         {0.0, 180.0, 0.0},
                                                         {0.0, -180.0, 5000.0},
                                                         {-33.9, 151.2, 99000.0}}};
inline constexpr double kImuDeltaGyro = 1e-4;  // rad/s per unit of IMU_D
inline constexpr double kImuDeltaAcc = 2e-3;   // m/s² per unit of IMU_D
inline constexpr size_t kMaxRecords = 3000;    // per input: keeps one execution well under a second

// Little-endian reads that yield zero past the end.
class ByteSource {
 public:
  ByteSource(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  bool done() const { return pos_ >= size_; }
  uint8_t U8() { return pos_ < size_ ? data_[pos_++] : 0; }
  int8_t I8() { return static_cast<int8_t>(U8()); }
  uint16_t U16() { return static_cast<uint16_t>(U8() | (U8() << 8)); }
  int16_t I16() { return static_cast<int16_t>(U16()); }
  int32_t I24() {
    const uint32_t u = U8() | (U8() << 8) | (static_cast<uint32_t>(U8()) << 16);
    return static_cast<int32_t>(u << 8) >> 8;  // sign-extended
  }
  int32_t I32() {
    const uint32_t u = U8() | (U8() << 8) | (static_cast<uint32_t>(U8()) << 16) | (static_cast<uint32_t>(U8()) << 24);
    return static_cast<int32_t>(u);
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

// x in int16 -> ±max, dense near zero (cubic), clamped to the range.
inline double Cubic16(int16_t x, double max) {
  const double u = static_cast<double>(x) / 32767.0;
  return std::clamp(max * u * u * u, -max, max);
}
inline int16_t Cubic16Inverse(double v, double max) {
  const double u = std::cbrt(std::clamp(v / max, -1.0, 1.0));
  return static_cast<int16_t>(std::lround(u * 32767.0));
}
inline double GnssSigma(uint8_t x) { return 1e-4 * std::pow(10.0, x / 32.0); }
inline double GvelSigma(uint8_t x) { return std::min(999.0, 1e-3 * std::pow(10.0, x / 40.0)); }

// The decoded options and stream.
class StreamDecoder {
 public:
  StreamDecoder(const uint8_t* data, size_t size);

  const Options& options() const { return options_; }
  // The next record; false at the end of the input (or after kMaxRecords).
  bool Next(LogRecord* record);

 private:
  struct Vehicle {
    Vec3 p = Vec3::Zero();  // ENU from the base, m
    double yaw = 0.0, speed = 0.0;
    Vec3 jump = Vec3::Zero();
  };
  void DecodeHeader();
  void DecodeOp();
  void RecordOp(Op op, double dt);
  void VehicleOp(bool drive, uint8_t sensors);
  void VehicleSample(uint8_t sensors, double accel, double yaw_rate);
  void VehicleOdom(double t);
  void VehicleFix(double t, uint8_t sensors);
  // The reader's time rules: older than the newest record -> dropped (out_of_order); the same type at the
  // same time -> dropped (duplicate); a burst holds one stamp.
  void Emit(LogRecord record, double t);
  double Noise(double amplitude);

  ByteSource in_;
  Options options_;
  GeodeticPoint base_;
  std::unique_ptr<LocalEnuFrame> base_frame_;
  double g_norm_ = kStandardGravity;
  std::deque<LogRecord> queue_;
  size_t emitted_ = 0;
  double t_ = 0.0;                  // newest time stamp
  std::array<double, kNumRecordTypes> last_t_;  // per type, -1: none yet
  int burst_ = 0;
  double burst_t_ = 0.0;
  ImuSample last_imu_;              // in the log's IMU axes
  double imu_dt_ = 0.01, grid_ = 0.0, jitter_ = 0.0, next_wheel_ = 0.0, next_fix_ = 0.0;
  int noise_ = 0, wheel_fault_ = 0, heading_fault_ = 0, mask_ = 0;
  double frozen_heading_ = -1.0;
  uint64_t rng_ = 0x9E3779B97F4A7C15ull;
  Vehicle car_;
};


// --- Decoding ------------------------------------------------------------------------------------------------

inline StreamDecoder::StreamDecoder(const uint8_t* data, size_t size) : in_(data, size) {
  last_t_.fill(-1.0);
  DecodeHeader();
}

inline void StreamDecoder::DecodeHeader() {
  const uint8_t h0 = in_.U8(), h1 = in_.U8(), h2 = in_.U8(), h3 = in_.U8();
  Options& o = options_;
  o.sensors.wheel.enabled = h0 & 1;
  o.sensors.gnss.use_heading = h0 & 2;
  o.init.wait_for_heading = h0 & 4;
  o.sensors.gnss.use_velocity = h0 & 8;
  o.standstill.enabled = h0 & 16;
  o.sensors.vehicle.nonholonomic = h0 & 32;
  o.eskf.estimate_gravity = h0 & 64;
  o.watchdog.enabled = h0 & 128;
  o.smoother.window_size = 2 + (h1 & 3);
  o.smoother.max_iterations = 1 + ((h1 >> 2) & 3);
  if (h1 & 16) o.smoother.linear_solver = "dense_schur";
  o.init.static_duration = (h1 & 32) ? 0.5 : 2.0;
  base_ = kBases[h3 & 7];
  if (h1 & 64) o.sensors.gnss.origin = base_;
  if (h1 & 128) {  // the edges of what the config accepts
    o.smoother.min_keyframe_interval = 0.0;
    o.smoother.max_keyframe_interval = 0.2;
    o.sensors.imu.max_gap = 0.05;
    o.watchdog.max_reject = 2.0;
    o.watchdog.max_position_sigma = 5.0;
  }
  switch ((h2 >> 6) & 3) {
    case 1:  // FRD
      o.sensors.imu.R_b_imu = Vec3(1.0, -1.0, -1.0).asDiagonal();
      break;
    case 2:  // RFU: body x = IMU y, body y = −IMU x
      o.sensors.imu.R_b_imu << 0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0;
      break;
    default:
      break;
  }
  t_ = kStartTimes[h2 & 15];
  imu_dt_ = kImuDt[(h2 >> 4) & 3];
  grid_ = t_ - imu_dt_;
  next_wheel_ = t_ + options_.sensors.wheel.interval;
  next_fix_ = t_;
  base_frame_ = std::make_unique<LocalEnuFrame>(base_);
  g_norm_ = NormalGravity(base_.lat_deg, base_.alt_m);
  last_imu_.acc = options_.sensors.imu.R_b_imu.transpose() * Vec3(0.0, 0.0, g_norm_);
}

inline bool StreamDecoder::Next(LogRecord* record) {
  while (queue_.empty()) {
    if (in_.done() || emitted_ >= kMaxRecords) return false;
    DecodeOp();
  }
  *record = queue_.front();
  queue_.pop_front();
  return true;
}

inline double StreamDecoder::Noise(double amplitude) {
  rng_ = rng_ * 6364136223846793005ull + 1442695040888963407ull;
  const double u = static_cast<double>(rng_ >> 11) * 0x1.0p-53;
  return amplitude * (2.0 * u - 1.0);
}

inline void StreamDecoder::Emit(LogRecord r, double t) {
  if (burst_ > 0) {
    if (burst_t_ < 0.0) burst_t_ = t;
    t = burst_t_;
    --burst_;
  }
  const size_t k = r.type_index();
  if (!(t >= t_) || last_t_[k] == t) return;  // out_of_order, duplicate
  r.set_t(t);
  t_ = t;
  last_t_[k] = t;
  queue_.push_back(r);
  ++emitted_;
}

inline void StreamDecoder::DecodeOp() {
  const uint8_t b = in_.U8();
  const Op op = static_cast<Op>(b & 15);
  const uint8_t param = b >> 4;
  switch (op) {
    case kOpImu:
    case kOpImuDelta:
    case kOpOdom:
    case kOpGnss:
    case kOpGvel:
      RecordOp(op, kSteps[param]);
      break;
    case kOpStand:
    case kOpDrive:
      VehicleOp(op == kOpDrive, param);
      break;
    case kOpGap:
      t_ += kGaps[param];
      grid_ += kGaps[param];
      break;
    case kOpBurst:
      burst_ = param + 1;
      burst_t_ = -1.0;
      break;
    case kOpRate:
      imu_dt_ = kImuDt[param & 7];
      break;
    case kOpJitter:
      jitter_ = kJitters[param & 7];
      break;
    case kOpNoise:
      noise_ = param & 3;
      break;
    case kOpJump: {
      const double angle = in_.U8() * (2.0 * kPi / 256.0);
      const double m = kJumps[param & 7];
      car_.jump = m * Vec3(std::cos(angle), std::sin(angle), (param & 8) ? 0.1 : 0.0);
      break;
    }
    case kOpWheels:
      wheel_fault_ = param & 3;
      break;
    case kOpHeading:
      heading_fault_ = param & 3;
      frozen_heading_ = -1.0;
      break;
    case kOpMask:
      mask_ = param;
      break;
  }
}

// A geodetic point the reader accepts, or false.
inline bool Plausible(GeodeticPoint* g) {
  g->alt_m = std::clamp(g->alt_m, -999.0, 99999.0);
  return IsPlausibleGeodetic(g->lat_deg, g->lon_deg, g->alt_m);
}

inline void StreamDecoder::RecordOp(Op op, double dt) {
  LogRecord r;
  if (op == kOpImu || op == kOpImuDelta) {
    ImuSample& imu = r.data.emplace<ImuSample>(last_imu_);
    for (int i = 0; i < 3; ++i) {
      imu.gyro[i] = op == kOpImu ? Cubic16(in_.I16(), log_limits::kMaxAbsGyro)
                                 : std::clamp(imu.gyro[i] + kImuDeltaGyro * in_.I8(), -log_limits::kMaxAbsGyro,
                                              log_limits::kMaxAbsGyro);
    }
    for (int i = 0; i < 3; ++i) {
      imu.acc[i] = op == kOpImu ? Cubic16(in_.I16(), log_limits::kMaxAbsAcc)
                                : std::clamp(imu.acc[i] + kImuDeltaAcc * in_.I8(), -log_limits::kMaxAbsAcc,
                                             log_limits::kMaxAbsAcc);
    }
    last_imu_ = imu;
  } else if (op == kOpOdom) {
    WheelRecord& wheel = r.data.emplace<WheelRecord>();
    wheel.left_pulses = in_.I24();
    wheel.right_pulses = in_.I24();
  } else if (op == kOpGnss) {
    GnssRecord& fix = r.data.emplace<GnssRecord>();
    const uint8_t flags = in_.U8();
    const int32_t a = in_.I32(), b = in_.I32(), c = in_.I32();
    GeodeticPoint g;
    if (flags & 4) {
      g = {std::clamp(a * (90.0 / 2147483648.0), -90.0, 90.0), std::clamp(b * (180.0 / 2147483648.0), -180.0, 180.0),
           c * 1e-4};
    } else {
      const double unit = (flags & 8) ? 1.0 : 1e-3;
      g = base_frame_->ToGeodetic(unit * Vec3(a, b, c));
    }
    const double heading = in_.U16() * (360.0 / 65536.0);
    fix.heading_valid = flags & 1;
    fix.heading_deg = fix.heading_valid ? heading : 0.0;
    fix.has_sigma = flags & 2;
    if (fix.has_sigma) fix.sigma_enu = Vec3(GnssSigma(in_.U8()), GnssSigma(in_.U8()), GnssSigma(in_.U8()));
    if (!Plausible(&g)) return;
    fix.lat_deg = g.lat_deg;
    fix.lon_deg = g.lon_deg;
    fix.alt_m = g.alt_m;
  } else {
    GnssVelocityRecord& velocity = r.data.emplace<GnssVelocityRecord>();
    const uint8_t flags = in_.U8();
    for (int i = 0; i < 3; ++i) velocity.v_enu[i] = Cubic16(in_.I16(), log_limits::kMaxAbsSpeed);
    velocity.has_sigma = flags & 1;
    if (velocity.has_sigma) velocity.sigma_enu = Vec3(GvelSigma(in_.U8()), GvelSigma(in_.U8()), GvelSigma(in_.U8()));
  }
  Emit(r, t_ + dt);
}

// --- The vehicle ---------------------------------------------------------------------------------------------

inline void StreamDecoder::VehicleOp(bool drive, uint8_t sensors) {
  const int n = 4 * (in_.U8() + 1);
  const double accel = drive ? 0.05 * in_.I8() : 0.0;
  const double yaw_rate = drive ? 0.005 * in_.I8() : 0.0;
  if (!drive) car_.speed = 0.0;
  grid_ = std::max(grid_, t_ - imu_dt_);
  for (int i = 0; i < n && emitted_ < kMaxRecords; ++i) VehicleSample(sensors, accel, yaw_rate);
}

inline void StreamDecoder::VehicleSample(uint8_t sensors, double accel, double yaw_rate) {
  constexpr double kMaxSpeed = 70.0;  // m/s
  const double dt = imu_dt_;
  grid_ += dt;
  const double T = grid_;
  const double a = (car_.speed > 0.0 || accel > 0.0) && !(car_.speed >= kMaxSpeed && accel > 0.0) ? accel : 0.0;
  car_.speed = std::clamp(car_.speed + a * dt, 0.0, kMaxSpeed);
  car_.yaw = WrapAngle(car_.yaw + yaw_rate * dt);
  car_.p += car_.speed * dt * Vec3(std::cos(car_.yaw), std::sin(car_.yaw), 0.0);

  const double gn = kNoiseGyro[noise_], an = kNoiseAcc[noise_];
  const Vec3 gyro_b(Noise(gn), Noise(gn), yaw_rate + Noise(gn));
  const Vec3 acc_b(a + Noise(an), car_.speed * yaw_rate + Noise(an), g_norm_ + Noise(an));
  const Mat3 R_imu_b = options_.sensors.imu.R_b_imu.transpose();
  last_imu_.gyro = (R_imu_b * gyro_b).cwiseMax(-log_limits::kMaxAbsGyro).cwiseMin(log_limits::kMaxAbsGyro);
  last_imu_.acc = (R_imu_b * acc_b).cwiseMax(-log_limits::kMaxAbsAcc).cwiseMin(log_limits::kMaxAbsAcc);
  const double imu_t = T + Noise(jitter_);
  const LogRecord imu{last_imu_};
  const bool with_imu = !(mask_ & 1);
  // In time order: the jittered IMU stamp may fall before or after the other sensors' epoch T.
  if (with_imu && imu_t <= T) Emit(imu, imu_t);
  if (next_wheel_ < T - options_.sensors.wheel.interval) next_wheel_ = T;  // after a gap: the next epoch is now
  if (next_wheel_ <= T + 1e-9) {
    if ((sensors & 1) && !(mask_ & 2)) VehicleOdom(T);
    next_wheel_ += options_.sensors.wheel.interval;
  }
  if (next_fix_ < T - 1.0) next_fix_ = T;
  if (next_fix_ <= T + 1e-9) {
    if ((sensors & 2) && !(mask_ & 4)) VehicleFix(T, sensors);
    next_fix_ += 1.0;
  }
  if (with_imu && imu_t > T) Emit(imu, imu_t);
}

inline void StreamDecoder::VehicleOdom(double t) {
  const WheelOptions& w = options_.sensors.wheel;
  if (wheel_fault_ == 1) return;  // silent
  double pulses = wheel_fault_ == 2 ? 0.0 : car_.speed * w.interval * w.pulses_per_rev / (2.0 * kPi * w.radius);
  if (wheel_fault_ == 3) pulses *= 2.0;
  const double counted = std::round(std::min(pulses, log_limits::kMaxAbsPulses - 1.0));
  Emit({WheelRecord{0.0, counted, counted}}, t);
}

inline void StreamDecoder::VehicleFix(double t, uint8_t sensors) {
  const Quat q = QuatFromYaw(car_.yaw);
  GeodeticPoint g = base_frame_->ToGeodetic(car_.p + q * options_.sensors.gnss.lever_b + car_.jump);
  if (!Plausible(&g)) return;
  LogRecord r;
  GnssRecord& fix = r.data.emplace<GnssRecord>();
  fix.lat_deg = g.lat_deg;
  fix.lon_deg = g.lon_deg;
  fix.alt_m = g.alt_m;
  fix.has_sigma = true;
  fix.sigma_enu = Vec3(0.02, 0.02, 0.03);
  fix.heading_valid = (sensors & 4) && heading_fault_ != 2;
  if (fix.heading_valid) {
    double heading = EnuYawToCompassDeg(car_.yaw + options_.sensors.gnss.mount_yaw) + (heading_fault_ == 3 ? 180.0 : 0.0);
    if (heading_fault_ == 1) {
      if (frozen_heading_ < 0.0) frozen_heading_ = heading;
      heading = frozen_heading_;
    }
    heading = std::fmod(heading, 360.0);
    fix.heading_deg = heading >= 0.0 && heading < 360.0 ? heading : 0.0;
  }
  Emit(r, t);
  if ((sensors & 8) && !(mask_ & 8)) {
    GnssVelocityRecord v;
    v.v_enu = car_.speed * Vec3(std::cos(car_.yaw), std::sin(car_.yaw), 0.0);
    Emit({v}, t);
  }
}

// The record as a line of the gins log format (all digits), for reproducing an input with `gins run`.
inline void PrintLine(const ImuSample& m, char* buf, size_t size) {
  std::snprintf(buf, size, "IMU %.17g %.17g %.17g %.17g %.17g %.17g %.17g", m.t, m.gyro.x(), m.gyro.y(),
                       m.gyro.z(), m.acc.x(), m.acc.y(), m.acc.z());
}

inline void PrintLine(const WheelRecord& w, char* buf, size_t size) {
  std::snprintf(buf, size, "ODOM %.17g %.17g %.17g", w.t, w.left_pulses, w.right_pulses);
}

inline void PrintLine(const GnssRecord& g, char* buf, size_t size) {
  const int n = std::snprintf(buf, size, "GNSS %.17g %.17g %.17g %.17g %.17g %d", g.t, g.lat_deg, g.lon_deg, g.alt_m,
                              g.heading_deg, g.heading_valid ? 1 : 0);
  if (g.has_sigma) {
    std::snprintf(buf + n, size - n, " %.17g %.17g %.17g", g.sigma_enu.x(), g.sigma_enu.y(), g.sigma_enu.z());
  }
}

inline void PrintLine(const GnssVelocityRecord& v, char* buf, size_t size) {
  const int n = std::snprintf(buf, size, "GVEL %.17g %.17g %.17g %.17g", v.t, v.v_enu.x(), v.v_enu.y(), v.v_enu.z());
  if (v.has_sigma) {
    std::snprintf(buf + n, size - n, " %.17g %.17g %.17g", v.sigma_enu.x(), v.sigma_enu.y(), v.sigma_enu.z());
  }
}

template <typename R>  // a measurement module's record: its token and numbers
void PrintLine(const R& r, char* buf, size_t size) {
  double v[RecordTraits<R>::kInfo.max_fields];
  const size_t n = R::Values(r, v);
  int at = std::snprintf(buf, size, "%s", RecordTraits<R>::kInfo.token);
  for (size_t i = 0; i < n && at > 0 && static_cast<size_t>(at) < size; ++i) {
    at += std::snprintf(buf + at, size - at, " %.17g", v[i]);
  }
}

inline std::string ToLogLine(const LogRecord& r) {
  char buf[320];
  std::visit([&buf](const auto& m) { PrintLine(m, buf, sizeof(buf)); }, r.data);
  return buf;
}

}  // namespace gins::fuzz
