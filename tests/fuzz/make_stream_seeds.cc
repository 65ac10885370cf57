// Writes the stream fuzzer's seeds (tests/fuzz/corpus/stream/) from slices of a gins log, encoded in the
// byte format of stream_format.h, plus a few made of the format's vehicle operations. Built with the fuzzers:
//   build-fuzz/tests/fuzz/make_stream_seeds data/sample/log.txt.gz tests/fuzz/corpus/stream
// and the other way, an input (a seed, a crash file) as a log and a config that `gins run` takes:
//   build-fuzz/tests/fuzz/make_stream_seeds --to-log INPUT OUT_DIR   (writes OUT_DIR/log.txt, config.yaml)
// Each slice starts with the log's first seconds (its standstill, so the estimators initialise) and may go
// on from a later time after a gap; the decoder's times then differ from the log's by rounding only.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <variant>
#include <vector>

#include "config/config_loader.h"
#include "fuzz/stream_format.h"

namespace gins::fuzz {
namespace {

constexpr size_t kSeedBytes = 3000;  // under the fuzzer's -max_len, and fast to run

class Encoder {
 public:
  Encoder(uint8_t h1, const GeodeticPoint& base) : frame_(base) {
    // h0: wheels, heading, wait for it, velocity, standstill, gravity, watchdog; h2: 1.7e9 s, 100 Hz, FLU.
    bytes_ = {0xDF, h1, 0x00, 0x00};
    last_imu_.acc = Vec3(0.0, 0.0, NormalGravity(base.lat_deg, base.alt_m));
  }

  const std::vector<uint8_t>& bytes() const { return bytes_; }
  double t() const { return t_; }

  void Add(const LogRecord& r) {
    AdvanceTo(r.t());
    const double dt = r.t() - t_;
    int code = 0;
    for (int k = 1; k < 16; ++k) {
      if (std::abs(kSteps[k] - dt) < std::abs(kSteps[code] - dt)) code = k;
    }
    const uint8_t param = static_cast<uint8_t>(code << 4);
    std::visit([this, param](const auto& m) { Encode(m, param); }, r.data);
    t_ += kSteps[code];
  }

  void Raw(std::initializer_list<uint8_t> b) { bytes_.insert(bytes_.end(), b); }

 private:
  // GAP operations, largest first, while the record is more than a second ahead.
  void AdvanceTo(double t) {
    for (int k = 15; k >= 0; --k) {
      while (t - t_ - kGaps[k] > 1.0) {
        Put(static_cast<uint8_t>(k << 4) | kOpGap);
        t_ += kGaps[k];
      }
    }
  }

  // A measurement module's record: the stream format has no operation for it, so a seed leaves it out.
  template <typename R>
  void Encode(const R& /*r*/, uint8_t /*param*/) {}

  void Encode(const ImuSample& s, uint8_t param) {
    std::array<long, 6> d;
    bool small = true;
    for (int i = 0; i < 3; ++i) {
      d[i] = std::lround((s.gyro[i] - last_imu_.gyro[i]) / kImuDeltaGyro);
      d[i + 3] = std::lround((s.acc[i] - last_imu_.acc[i]) / kImuDeltaAcc);
    }
    for (long x : d) small = small && x >= -128 && x <= 127;
    if (small) {
      Put(param | kOpImuDelta);
      for (int i = 0; i < 6; ++i) Put(static_cast<uint8_t>(static_cast<int8_t>(d[i])));
      for (int i = 0; i < 3; ++i) {  // as the decoder adds them
        last_imu_.gyro[i] += kImuDeltaGyro * static_cast<int8_t>(d[i]);
        last_imu_.acc[i] += kImuDeltaAcc * static_cast<int8_t>(d[i + 3]);
      }
      return;
    }
    Put(param | kOpImu);
    for (int i = 0; i < 3; ++i) {
      const int16_t x = Cubic16Inverse(s.gyro[i], log_limits::kMaxAbsGyro);
      Put16(x);
      last_imu_.gyro[i] = Cubic16(x, log_limits::kMaxAbsGyro);
    }
    for (int i = 0; i < 3; ++i) {
      const int16_t x = Cubic16Inverse(s.acc[i], log_limits::kMaxAbsAcc);
      Put16(x);
      last_imu_.acc[i] = Cubic16(x, log_limits::kMaxAbsAcc);
    }
  }

  void Encode(const WheelRecord& w, uint8_t param) {
    Put(param | kOpOdom);
    Put24(static_cast<int32_t>(w.left_pulses));
    Put24(static_cast<int32_t>(w.right_pulses));
  }

  void Encode(const GnssVelocityRecord& v, uint8_t param) {
    Put(param | kOpGvel);
    Put(0);
    for (int i = 0; i < 3; ++i) Put16(Cubic16Inverse(v.v_enu[i], log_limits::kMaxAbsSpeed));
  }

  void Encode(const GnssRecord& g, uint8_t param) {
    Put(param | kOpGnss);
    Put(static_cast<uint8_t>((g.heading_valid ? 1 : 0) | (g.has_sigma ? 2 : 0)));  // relative, mm
    const Vec3 p = frame_.ToEnu({g.lat_deg, g.lon_deg, g.alt_m}) * 1e3;
    for (int i = 0; i < 3; ++i) Put32(static_cast<int32_t>(std::lround(p[i])));
    Put16(static_cast<uint16_t>(std::lround(g.heading_deg * 65536.0 / 360.0) % 65536));
    if (!g.has_sigma) return;
    for (int i = 0; i < 3; ++i) {
      Put(static_cast<uint8_t>(std::clamp(std::lround(32.0 * std::log10(g.sigma_enu[i] / 1e-4)), 0L, 255L)));
    }
  }

  void Put(uint8_t b) { bytes_.push_back(b); }
  void Put16(uint16_t x) {
    Put(x & 0xFF);
    Put(x >> 8);
  }
  void Put16(int16_t x) { Put16(static_cast<uint16_t>(x)); }
  void Put24(int32_t x) {
    for (int i = 0; i < 3; ++i) Put(static_cast<uint8_t>((static_cast<uint32_t>(x) >> (8 * i)) & 0xFF));
  }
  void Put32(int32_t x) {
    for (int i = 0; i < 4; ++i) Put(static_cast<uint8_t>((static_cast<uint32_t>(x) >> (8 * i)) & 0xFF));
  }

  LocalEnuFrame frame_;
  std::vector<uint8_t> bytes_;
  double t_ = kStartTimes[0];
  ImuSample last_imu_;
};

std::vector<LogRecord> ReadLog(const std::string& path) {
  LogReader reader(path, InputOptions{});
  std::vector<LogRecord> records;
  LogRecord r;
  while (reader.Next(&r)) records.push_back(r);
  return records;
}

void Write(const std::string& dir, const std::string& name, const std::vector<uint8_t>& bytes) {
  std::ofstream out(dir + "/" + name, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  std::printf("%s: %zu bytes\n", name.c_str(), bytes.size());
}

// The log's first `head` seconds, then from `from` seconds on, until the seed is full.
std::vector<uint8_t> Slice(const std::vector<LogRecord>& log, uint8_t h1, double head, double from) {
  Encoder e(h1, kBases[0]);
  const double t0 = log.front().t();
  for (const LogRecord& r : log) {
    const double s = r.t() - t0;
    if (s >= head && s < from) continue;
    if (e.bytes().size() > kSeedBytes) break;
    e.Add(r);
  }
  return e.bytes();
}

// The input's records as OUT_DIR/log.txt and its options as OUT_DIR/config.yaml.
int ToLog(const std::string& input, const std::string& dir) {
  std::ifstream in(input, std::ios::binary);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  StreamDecoder decoder(bytes.data(), bytes.size());
  std::ofstream(dir + "/config.yaml") << OptionsToYaml(decoder.options());
  std::ofstream log(dir + "/log.txt");
  LogRecord r;
  size_t n = 0;
  while (decoder.Next(&r)) {
    log << ToLogLine(r) << '\n';
    ++n;
  }
  std::printf("%s: %zu records -> %s/log.txt, %s/config.yaml\n", input.c_str(), n, dir.c_str(), dir.c_str());
  return 0;
}

}  // namespace
}  // namespace gins::fuzz

int main(int argc, char** argv) {
  using gins::fuzz::Slice;
  if (argc == 4 && std::string(argv[1]) == "--to-log") return gins::fuzz::ToLog(argv[2], argv[3]);
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_stream_seeds LOG OUT_DIR | make_stream_seeds --to-log INPUT OUT_DIR\n");
    return 2;
  }
  const std::vector<gins::LogRecord> log = gins::fuzz::ReadLog(argv[1]);
  const std::string dir = argv[2];
  constexpr uint8_t kH1 = 0x0A;           // window 4, 3 iterations, 2 s standstill
  constexpr uint8_t kH1Short = kH1 | 32;  // 0.5 s standstill
  gins::fuzz::Write(dir, "sample_start", Slice(log, kH1, 1e9, 1e9));
  gins::fuzz::Write(dir, "sample_start_short_init", Slice(log, kH1Short, 1e9, 1e9));
  gins::fuzz::Write(dir, "sample_drive_off_18s", Slice(log, kH1, 3.5, 18.0));
  gins::fuzz::Write(dir, "sample_turn_40s", Slice(log, kH1Short, 1.5, 40.0));
  gins::fuzz::Write(dir, "sample_stop_116s", Slice(log, kH1Short, 1.5, 116.0));
  gins::fuzz::Write(dir, "sample_outage_138s", Slice(log, kH1Short, 1.5, 138.0));
  gins::fuzz::Write(dir, "sample_no_standstill_60s", Slice(log, kH1, 0.0, 60.0));
  // The start again with other options: the config's edges (bit 7), the origin given (6), dense Schur (4).
  gins::fuzz::Write(dir, "sample_start_edge_options", Slice(log, kH1Short | 128, 1e9, 1e9));
  gins::fuzz::Write(dir, "sample_start_origin_dense", Slice(log, kH1Short | 64 | 16, 1e9, 1e9));
  // The format's vehicle: 3 s standing with wheels and fixes with heading (0x75: STAND, sensors 0b0111), then
  // driving off (DRIVE 0xF6: all sensors, +1 m/s², then a turn at 0.1 rad/s).
  gins::fuzz::Encoder v(kH1, gins::fuzz::kBases[0]);
  v.Raw({0x75, 74, 0xF6, 49, 20, 0, 0xF6, 99, 0, 20, 0xF6, 49, 236, 0});
  gins::fuzz::Write(dir, "vehicle_stand_drive", v.bytes());
  // The same with field faults: jitter 20 ms (0x5A), the fixes 1 km off for 20 s (JUMP 0x4C, back 0x0C), the
  // wheels at zero pulses (0x2D), the heading frozen (0x1E), GVEL with each fix, 10 s without GNSS (MASK 0x4F).
  gins::fuzz::Encoder f(kH1, gins::fuzz::kBases[0]);
  f.Raw({0x75, 74, 0xF6, 49, 20, 0, 0x5A, 0xF6, 24, 0, 10, 0x4C, 64, 0xF6, 49, 0, 0, 0x0C, 0, 0x2D, 0x1E, 0xF6,
         49, 0, 20, 0x4F, 0xF6, 49, 0, 0, 0x0F, 0xF6, 49, 236, 0});
  gins::fuzz::Write(dir, "vehicle_faults", f.bytes());
  return 0;
}
