// The public API's small parts (gins/gins.h): version, names, attitude helpers, Config, LogReader.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include "apps/api/access.h"
#include "apps/api/convert.h"
#include "apps/api/version.h"
#include "config/config_loader.h"
#include "gins/gins.h"

namespace gins::api {

const char* Version() { return GINS_VERSION; }

double Record::t() const {
  switch (type) {
    case Type::kImu:
      return imu.t;
    case Type::kWheel:
      return wheel.t;
    case Type::kGnss:
      return gnss.t;
    case Type::kGnssVelocity:
      return gnss_velocity.t;
    case Type::kOther:
      return other.values.empty() ? 0.0 : other.values[0];
  }
  return imu.t;
}

const char* ModeName(Mode mode) {
  switch (mode) {
    case Mode::kEskf:
      return "eskf";
    case Mode::kSmoother:
      return "smoother";
    case Mode::kBoth:
      return "both";
    case Mode::kBatch:
      return "batch";
    case Mode::kAll:
      return "all";
  }
  return "?";
}

bool ParseMode(const std::string& name, Mode* mode) {
  for (const Mode m : {Mode::kEskf, Mode::kSmoother, Mode::kBoth, Mode::kBatch, Mode::kAll}) {
    if (name == ModeName(m)) {
      *mode = m;
      return true;
    }
  }
  return false;
}

const char* StreamName(Stream stream) {
  switch (stream) {
    case Stream::kEskf:
      return "eskf";
    case Stream::kSmoother:
      return "smoother";
    case Stream::kSmootherOnline:
      return "smoother_online";
    case Stream::kBatch:
      return "batch";
    case Stream::kEskfRts:
      return "eskf_rts";
  }
  return "?";
}

void RollPitchYawDeg(const State& state, double rpy_deg[3]) {
  const Quat q(state.q_wb[0], state.q_wb[1], state.q_wb[2], state.q_wb[3]);
  const Mat3 R = q.normalized().toRotationMatrix();
  // R = Rz(yaw) Ry(pitch) Rx(roll).
  rpy_deg[0] = std::atan2(R(2, 1), R(2, 2)) * kRadToDeg;
  rpy_deg[1] = std::asin(std::clamp(-R(2, 0), -1.0, 1.0)) * kRadToDeg;
  rpy_deg[2] = std::atan2(R(1, 0), R(0, 0)) * kRadToDeg;
}

double HeadingDeg(const State& state) {
  const Quat q(state.q_wb[0], state.q_wb[1], state.q_wb[2], state.q_wb[3]);
  const Vec3 x_w = q.normalized() * Vec3::UnitX();
  return EnuYawToCompassDeg(std::atan2(x_w.y(), x_w.x()));
}

// --- Config -------------------------------------------------------------------------------------------------

struct Config::Impl {
  Options options;
};

Config::Config() : impl_(std::make_shared<const Impl>()) {}
Config::Config(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}
Config::~Config() = default;
Config::Config(const Config&) = default;
Config& Config::operator=(const Config&) = default;

Config Config::FromFile(const std::string& path) {
  try {
    return Config(std::make_shared<const Impl>(Impl{LoadOptions(path)}));
  } catch (const ConfigError& e) {
    throw Error(Error::Kind::kConfig, e.what());
  }
}

Config Config::FromYaml(const std::string& yaml, const std::string& name) {
  try {
    return Config(std::make_shared<const Impl>(Impl{LoadOptionsFromString(yaml, name)}));
  } catch (const ConfigError& e) {
    throw Error(Error::Kind::kConfig, e.what());
  }
}

std::string Config::ToYaml() const { return OptionsToYaml(impl_->options); }
double Config::reorder_window_s() const { return impl_->options.input.reorder_window; }

// --- LogReader ----------------------------------------------------------------------------------------------

struct LogReader::Impl {
  explicit Impl(std::unique_ptr<::gins::LogReader> r) : reader(std::move(r)) {}
  std::unique_ptr<::gins::LogReader> reader;
  LogRecord record;
};

namespace {

// The reader's InputError is the API's Error(kInput), with the same one-line message.
template <typename F>
auto InputErrors(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const InputError& e) {
    throw Error(Error::Kind::kInput, e.what());
  }
}

}  // namespace

LogReader::LogReader(const std::string& path, const Config& config)
    : impl_(InputErrors([&] {
        return std::make_unique<Impl>(std::make_unique<::gins::LogReader>(path, ReaderOptions(config.impl_->options)));
      })) {}

LogReader::LogReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

LogReader LogReader::FromFd(int fd, const std::string& name, const Config& config, int stop_fd) {
  return LogReader(std::make_unique<Impl>(
      std::make_unique<::gins::LogReader>(fd, name, ReaderOptions(config.impl_->options), stop_fd)));
}

LogReader::~LogReader() = default;
LogReader::LogReader(LogReader&&) noexcept = default;
LogReader& LogReader::operator=(LogReader&&) noexcept = default;

bool LogReader::Next(Record* record) {
  return InputErrors([&] {
    if (!impl_->reader->Next(&impl_->record)) return false;
    *record = ToRecord(impl_->record);
    return true;
  });
}

ReadCounts LogReader::counts() const {
  const ReadStats& s = impl_->reader->stats();
  return {s.lines,
          CountOf<ImuSample>(s.records),
          CountOf<WheelRecord>(s.records),
          CountOf<GnssRecord>(s.records),
          CountOf<GnssVelocityRecord>(s.records),
          s.total_skipped()};
}

bool LogReader::stopped() const { return impl_->reader->stopped(); }

// --- internal::Access ---------------------------------------------------------------------------------------

const Options& internal::Access::options(const Config& config) { return config.impl_->options; }

Config internal::Access::MakeConfig(const Options& options) {
  return Config(std::make_shared<const Config::Impl>(Config::Impl{options}));
}

const ReadStats& internal::Access::read_stats(const LogReader& reader) { return reader.impl_->reader->stats(); }

}  // namespace gins::api
