// gins as a library: push measurements into a session, get each estimated state back.
//
// The whole public API is this header (installed as <gins/gins.h>, CMake target gins::gins). It needs only
// the C++17 standard library: no Eigen, no Ceres, none of gins's internals. `gins run` and `gins stream`
// are built on it. docs/api.md has a usage example.
//
// Conventions, stated once (in full: docs/formats.md §2):
//   - World frame w: local East-North-Up tangent plane at the origin: gnss.origin if the config sets one,
//     else the first usable GNSS fix.
//   - Body frame b: the IMU frame after the config's imu.axes mapping, x forward, y left, z up (FLU).
//   - q_wb: Hamilton quaternion stored (w, x, y, z); it rotates body vectors into w.
//   - Units SI (m, s, rad, m/s², rad/s) unless a name says deg; time in seconds on the log's own clock
//     (unix, GPS, anything), the same for every sensor.
//
// Time order: each measurement is stamped with its own time. Those that arrive older than the newest one
// pushed by up to input.reorder_window_s are sorted into place (so every measurement reaches the
// estimators that much later); older ones are rejected and counted ("late"). Records of different types
// may share a time stamp.
//
// Threads: a Session, a LogReader and a Config are not thread-safe; use each from one thread at a time.
// Callbacks run on the thread that pushes, inside Push() or Finish().
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace gins {
namespace api {

namespace internal {
class Access;  // gins's own tools (`gins run`) reach the session's internals through it
}

// The library's version, "major.minor.patch" (CMakeLists.txt's project()).
const char* Version();

// Every error the API reports. what() is one line naming the file, line or key and the reason.
class Error : public std::runtime_error {
 public:
  enum class Kind {
    kConfig,      // the config does not load (unknown key, bad value, unreadable file)
    kInput,       // a log cannot be read, or is too damaged (input.on_error, input.max_errors), or its IMU's
                  // units or axes are wrong (the first records: the accelerometer in g, z pointing down)
    kNoSolution,  // Finish() without an initialisation (no standstill, no GNSS, ...)
    kUsage,       // the API called out of turn (e.g. Push after Finish)
  };
  Error(Kind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

// --- Measurements, as logged (the log format of docs/formats.md §3, one struct per type) --------------------

struct Imu {  // IMU record
  double t = 0.0;
  double gyro[3] = {0, 0, 0};  // rad/s, in the IMU's axes (imu.axes maps them into the body frame)
  double acc[3] = {0, 0, 0};   // m/s², specific force, the same axes
};

struct Wheel {  // ODOM record
  double t = 0.0;
  double left_pulses = 0.0;  // encoder pulses counted over (t - wheel.interval_s, t]
  double right_pulses = 0.0;
};

struct Gnss {  // GNSS record
  double t = 0.0;
  double lat_deg = 0.0, lon_deg = 0.0;
  double alt_m = 0.0;        // ellipsoidal height
  double heading_deg = 0.0;  // dual-antenna baseline, clockwise from true north
  bool heading_valid = false;
  bool has_sigma = false;           // sigma_enu holds the fix's 1-σ (else the config's gnss.sigma_m)
  double sigma_enu[3] = {0, 0, 0};  // m, east, north, up
};

struct GnssVelocity {  // GVEL record
  double t = 0.0;
  double v_enu[3] = {0, 0, 0};  // antenna velocity, m/s, local east, north, up at the fix
  bool has_sigma = false;
  double sigma_enu[3] = {0, 0, 0};  // m/s
};

// A record of a type this header has no struct for (a measurement module's, e.g. BARO: docs/formats.md §3),
// as its log line has it: the type token and the numbers after it, the time first.
struct OtherRecord {
  std::string type;            // "BARO"
  std::vector<double> values;  // t, then the fields
};

// Any of them: what a LogReader yields and Session::Push takes.
struct Record {
  enum class Type { kImu, kWheel, kGnss, kGnssVelocity, kOther };
  Type type = Type::kImu;
  uint64_t line = 0;  // the line in the log (LogReader); 0 for records made in code
  Imu imu;            // the member that type names is the one that counts
  Wheel wheel;
  Gnss gnss;
  GnssVelocity gnss_velocity;
  OtherRecord other;
  double t() const;
};

// --- Estimates ----------------------------------------------------------------------------------------------

// kBatch: the whole-log smoother (after the sliding window's forward pass, which it starts from); kAll:
// the ESKF with its RTS pass, the window and the batch. The smoothed streams come at Session::Finish.
enum class Mode { kEskf, kSmoother, kBoth, kBatch, kAll };
const char* ModeName(Mode mode);                      // "eskf", "smoother", "both", "batch", "all"
bool ParseMode(const std::string& name, Mode* mode);  // false for an unknown name

// Which estimate a state belongs to.
enum class Stream {
  kEskf,            // the filter: one state per IMU sample, delivered by the push of that sample
  kSmoother,        // the smoother's final estimate: each keyframe when it leaves the window, then the
                    // IMU-rate states after it (delayed by the window, smoother.window_size keyframes)
  kSmootherOnline,  // the smoother's newest keyframe after each solve: causal, rougher
  kBatch,           // the whole-log smoother: every keyframe and IMU-rate state, at Finish
  kEskfRts,         // the ESKF smoothed by its Rauch-Tung-Striebel backward pass, at Finish
};
// "eskf", "smoother", "smoother_online", "batch", "eskf_rts" (`gins run`'s file names)
const char* StreamName(Stream stream);

struct Geodetic {
  double lat_deg = 0.0, lon_deg = 0.0, alt_m = 0.0;
};

// One estimate. The states of a stream come in time order; one may repeat the time of the one before it
// (a measurement update at that time): the later supersedes it.
struct State {
  Stream stream = Stream::kEskf;
  double t = 0.0;
  double p_enu[3] = {0, 0, 0};      // body origin in w, m
  double lla[3] = {0, 0, 0};        // the same point: latitude, longitude (deg), ellipsoidal height (m);
                                    // NaN when SessionOptions::geodetic is off
  double v_enu[3] = {0, 0, 0};      // m/s, in w
  double q_wb[4] = {1, 0, 0, 0};    // w, x, y, z
  double gyro_bias[3] = {0, 0, 0};  // rad/s
  double acc_bias[3] = {0, 0, 0};   // m/s²
  double sigma_p[3] = {0, 0, 0};    // 1-σ of p_enu, m
  double sigma_v[3] = {0, 0, 0};    // 1-σ of v_enu, m/s
  double sigma_att[3] = {0, 0, 0};  // 1-σ of the attitude about the E, N, U axes, rad (the last is yaw)
  double odom_scale = 1.0;          // wheel odometer scale factor
};

// Attitude of a state: roll about x, pitch about y, yaw about z (ZYX order) in deg, yaw counter-clockwise
// from east; and the compass heading of the body's x axis, deg clockwise from true north in [0, 360).
void RollPitchYawDeg(const State& state, double rpy_deg[3]);
double HeadingDeg(const State& state);

// --- Configuration ------------------------------------------------------------------------------------------

// A loaded and validated config (every key of config/default.yaml). Immutable; cheap to copy.
class Config {
 public:
  Config();  // the defaults (config/default.yaml)
  // Throw Error(kConfig) naming the file (or `name`), the key and the line.
  static Config FromFile(const std::string& path);
  static Config FromYaml(const std::string& yaml, const std::string& name = "<yaml>");
  std::string ToYaml() const;  // the effective config, every key, in the users' units
  double reorder_window_s() const;

  ~Config();
  Config(const Config&);
  Config& operator=(const Config&);

 private:
  friend class Session;
  friend class LogReader;
  friend class internal::Access;
  struct Impl;
  explicit Config(std::shared_ptr<const Impl> impl);
  std::shared_ptr<const Impl> impl_;
};

// --- Status -------------------------------------------------------------------------------------------------

// One kind of measurement that was not used, and how often.
struct Rejection {
  std::string source;       // "input": refused by the session; or the estimator: "eskf", "smoother"
  std::string measurement;  // input: "imu", "wheel", "gnss", "gnss_velocity"; an estimator's own names:
                            // "gnss_position", "gnss_heading", "gnss_velocity", "wheel", "zero_velocity", ...
  std::string reason;       // input: "late" (older than the reorder window) or the log's damage reasons
                            // ("non_finite", "absurd_value"); an estimator's: "chi2_gate", ...
  uint64_t count = 0;
};

struct Status {
  bool initialized = false;
  std::string diagnosis;                     // why there is no solution yet; "initialised" once there is
  bool init_timed_out = false;               // still not initialised init.max_wait_s after the first measurement
  std::optional<Geodetic> origin;            // of w, once known
  double first_time = 0.0, last_time = 0.0;  // of the measurements taken (0 before the first)
  uint64_t accepted = 0;                     // measurements taken
  uint64_t reordered = 0;                    // of them: arrived out of order within the window, sorted into place
  uint64_t rejected = 0;                     // refused by the session: late or invalid (in rejections, source "input")
  uint64_t states = 0;                       // states delivered
  uint64_t states_dropped = 0;               // polling: dropped because the queue was full (oldest first)
  uint64_t callback_errors = 0;              // state callbacks that threw
  uint64_t watchdog_resets = 0;              // re-initialisations from GNSS after divergence, over all estimators
  std::vector<Rejection> rejections;
};

// --- Session ------------------------------------------------------------------------------------------------

struct SessionOptions {
  Mode mode = Mode::kEskf;
  bool geodetic = true;               // fill State::lla (about 0.2 µs a state)
  size_t max_queued_states = 100000;  // polling: the queue's bound
  // With more than one estimator (kBoth, kAll): each on a thread of its own. Every stream is the same, bit
  // for bit; the callback (or the queue) is then fed from those threads, one call at a time, each stream
  // in its own order; status() counts the other estimators' rejections once Finish has returned. What the
  // callback uses must outlive the Session (destroying it stops the threads).
  bool parallel = false;
};

using StateCallback = std::function<void(const State&)>;

class Session {
 public:
  explicit Session(const Config& config, const SessionOptions& options = {});
  Session(const Config& config, Mode mode);
  ~Session();
  Session(Session&&) noexcept;
  Session& operator=(Session&&) noexcept;
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  // Where states go: without a callback they queue for Poll(). Set it before the first push.
  //
  // A callback that throws does not corrupt the session: the exception is caught where the estimator
  // called out, the estimator finishes its step, later states of the same call still go to the callback,
  // and then the first exception is rethrown from the Push() or Finish() that produced the state. The
  // measurement counts as taken; the session goes on with the next push (status().callback_errors).
  void OnState(StateCallback callback);

  // True if the measurement was taken; false if refused, with the reason in status().rejections: a
  // value that is not finite or not plausible (the log reader's checks), or older than the newest
  // measurement by more than input.reorder_window_s. Throws Error(kUsage) after Finish(), Error(kInput) when the
  // first IMU records show wrong units or axes (the reason in what()).
  bool Push(const Imu& imu);
  bool Push(const Wheel& wheel);
  bool Push(const Gnss& fix);
  bool Push(const GnssVelocity& velocity);
  bool Push(const Record& record);

  // End of the data: what the reorder buffer holds goes to the estimators, which flush (the smoother
  // delivers its window). Throws Error(kNoSolution) if the session never initialised.
  void Finish();

  // The oldest queued state (no callback set); false when there is none.
  bool Poll(State* state);

  bool initialized() const;
  // Not initialised init.max_wait_s after the first measurement (`gins run` gives up then).
  bool init_timed_out() const;
  Status status() const;
  // Everything the session counts, as JSON text: initialisation, each estimator's statistics (used and
  // rejected measurements by reason, watchdog, solver), GNSS outages (the "estimators" and
  // "initialization" objects of `gins run`'s summary.json, and more).
  std::string StatsJson() const;

 private:
  friend class internal::Access;
  class Impl;
  std::unique_ptr<Impl> impl_;
};

// --- Reading a log ------------------------------------------------------------------------------------------

struct ReadCounts {
  uint64_t lines = 0;
  uint64_t imu = 0, wheel = 0, gnss = 0, gnss_velocity = 0;  // records read
  uint64_t skipped = 0;                                      // damaged lines skipped (input.on_error: skip)
};

// A log in the gins format (docs/formats.md §3), with the damage policy of the config's input.* keys: damaged lines
// are skipped and counted, or stop the read (Error(kInput) naming the file, line and reason).
class LogReader {
 public:
  // A file, plain or gzip. Throws Error(kInput) if it cannot be opened.
  LogReader(const std::string& path, const Config& config);
  // A pipe, socket or terminal read as it arrives (plain text): each line is handed on as soon as its
  // newline is read. When stop_fd (>= 0) becomes readable (e.g. a signalfd), the data ends after the
  // last complete line read and stopped() is true. `name` stands for the file in messages.
  static LogReader FromFd(int fd, const std::string& name, const Config& config, int stop_fd = -1);
  ~LogReader();
  LogReader(LogReader&&) noexcept;
  LogReader& operator=(LogReader&&) noexcept;

  // The next record; false at the end of the data.
  bool Next(Record* record);
  ReadCounts counts() const;
  bool stopped() const;

 private:
  friend class internal::Access;
  struct Impl;
  explicit LogReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace api
}  // namespace gins
