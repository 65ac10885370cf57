// gins._gins.Session: the push API (gins::api::Session) for Python. Every push takes one measurement or n
// of them as numpy arrays, looped over here, in C++, with the GIL released; a Python state callback takes
// the GIL back for each state, and an exception it raises is rethrown from the push that produced the state
// (the API's rule: the estimator finishes its step first). States without a callback queue in the API and
// are drained by poll() into numpy columns.
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "apps/python/bindings.h"
#include "gins/gins.h"

namespace gins::python {

py::ssize_t Records(const DoubleArray& a, py::ssize_t width, const char* name) {
  if (width == 1 && a.ndim() == 0) return -1;
  if (width == 1 && a.ndim() == 1) return a.shape(0);
  if (width > 1 && a.ndim() == 1 && a.shape(0) == width) return -1;
  if (width > 1 && a.ndim() == 2 && a.shape(1) == width) return a.shape(0);
  throw py::value_error(std::string(name) + ": expected " +
                        (width == 1 ? "a number or an array of n" : "3 numbers or an n×3 array") + ", got shape " +
                        py::str(a.attr("shape")).cast<std::string>());
}

namespace {

using namespace pybind11::literals;

// An argument read as record i's `width` numbers: a 1-D or n×width array, or one value for every record
// (stride 0).
struct Column {
  const double* data = nullptr;
  py::ssize_t stride = 0;
  const double* at(py::ssize_t i) const { return data + i * stride; }
  double operator[](py::ssize_t i) const { return data[i * stride]; }
};

// The records of one push: n (-1 for a single one) and each argument as a Column. The first argument sets
// n; the others must agree, or (optional ones, broadcast) be a single value.
class Batch {
 public:
  Column Required(const DoubleArray& a, py::ssize_t width, const char* name) {
    const py::ssize_t n = Records(a, width, name);
    if (!first_) {
      first_ = true;
      n_ = n;
    } else if (n != n_) {
      throw py::value_error(std::string(name) + ": " + Count(n) + " where the time stamps give " + Count(n_));
    }
    return {a.data(), n < 0 ? 0 : width};
  }
  Column Broadcast(const DoubleArray& a, py::ssize_t width, const char* name) {
    const py::ssize_t n = Records(a, width, name);
    if (n >= 0 && n != n_) {
      throw py::value_error(std::string(name) + ": " + Count(n) + " where the time stamps give " + Count(n_));
    }
    return {a.data(), n < 0 ? 0 : width};
  }
  py::ssize_t n() const { return n_; }

 private:
  static std::string Count(py::ssize_t n) { return n < 0 ? "one record" : std::to_string(n) + " records"; }
  bool first_ = false;
  py::ssize_t n_ = -1;
};

// σ given as NaN (or not at all) is no σ: the config's value applies.
bool CopySigma(const Column* sigma, py::ssize_t i, double out[3]) {
  if (sigma == nullptr) return false;
  const double* s = sigma->at(i);
  if (std::isnan(s[0]) || std::isnan(s[1]) || std::isnan(s[2])) return false;
  std::copy(s, s + 3, out);
  return true;
}

api::Imu MakeImu(const Column& t, const Column& gyro, const Column& acc, py::ssize_t i) {
  api::Imu m;
  m.t = t[i];
  std::copy(gyro.at(i), gyro.at(i) + 3, m.gyro);
  std::copy(acc.at(i), acc.at(i) + 3, m.acc);
  return m;
}

api::Wheel MakeWheel(const Column& t, const Column& left, const Column& right, py::ssize_t i) {
  return api::Wheel{t[i], left[i], right[i]};
}

struct GnssColumns {
  Column t, lat, lon, alt, heading, valid;
  std::optional<Column> sigma;
  api::Gnss Make(py::ssize_t i) const {
    api::Gnss g;
    g.t = t[i];
    g.lat_deg = lat[i];
    g.lon_deg = lon[i];
    g.alt_m = alt[i];
    g.heading_deg = heading[i];
    g.heading_valid = valid[i] != 0.0;
    g.has_sigma = CopySigma(sigma ? &*sigma : nullptr, i, g.sigma_enu);
    return g;
  }
};

struct GnssVelocityColumns {
  Column t, v;
  std::optional<Column> sigma;
  api::GnssVelocity Make(py::ssize_t i) const {
    api::GnssVelocity m;
    m.t = t[i];
    std::copy(v.at(i), v.at(i) + 3, m.v_enu);
    m.has_sigma = CopySigma(sigma ? &*sigma : nullptr, i, m.sigma_enu);
    return m;
  }
};

std::optional<DoubleArray> OptionalArray(const py::object& o) {
  if (o.is_none()) return std::nullopt;
  return py::cast<DoubleArray>(o);
}

class PySession {
 public:
  PySession(const api::Config& config, const std::string& mode, bool parallel, bool geodetic, size_t max_queued) {
    api::SessionOptions options;
    if (!api::ParseMode(mode, &options.mode)) {
      throw py::value_error("unknown mode '" + mode + "' (eskf, smoother, both, batch, all)");
    }
    options.parallel = parallel;
    options.geodetic = geodetic;
    options.max_queued_states = max_queued;
    session_ = std::make_unique<api::Session>(config, options);
  }
  // The estimators' threads (parallel) may be waiting for the GIL in the callback: they stop without it.
  ~PySession() {
    py::gil_scoped_release release;
    session_.reset();
  }
  PySession(const PySession&) = delete;
  PySession& operator=(const PySession&) = delete;

  void OnState(py::object callback) {
    Guard guard(this);
    if (pushed_) ThrowUsage("gins.Session.on_state: set the callback before the first push");
    if (callback.is_none()) {
      session_->OnState(nullptr);
      callback_ = py::none();
      return;
    }
    if (!PyCallable_Check(callback.ptr())) throw py::type_error("on_state: the callback must be callable");
    callback_ = std::move(callback);
    session_->OnState([this](const api::State& s) {
      py::gil_scoped_acquire gil;
      callback_(py::cast(s, py::return_value_policy::copy));  // raises py::error_already_set
    });
  }

  py::object PushImu(const DoubleArray& t, const DoubleArray& gyro, const DoubleArray& acc) {
    Batch b;
    const Column ct = b.Required(t, 1, "t"), cg = b.Required(gyro, 3, "gyro"), ca = b.Required(acc, 3, "acc");
    return PushAll(b.n(), [&](py::ssize_t i) { return MakeImu(ct, cg, ca, i); });
  }

  py::object PushWheel(const DoubleArray& t, const DoubleArray& left, const DoubleArray& right) {
    Batch b;
    const Column ct = b.Required(t, 1, "t"), cl = b.Required(left, 1, "left_pulses"),
                 cr = b.Required(right, 1, "right_pulses");
    return PushAll(b.n(), [&](py::ssize_t i) { return MakeWheel(ct, cl, cr, i); });
  }

  py::object PushGnss(const DoubleArray& t, const DoubleArray& lat, const DoubleArray& lon, const DoubleArray& alt,
                      const DoubleArray& heading, const DoubleArray& valid, const py::object& sigma) {
    Batch b;
    GnssColumns g{b.Required(t, 1, "t"),
                  b.Required(lat, 1, "lat_deg"),
                  b.Required(lon, 1, "lon_deg"),
                  b.Required(alt, 1, "alt_m"),
                  b.Broadcast(heading, 1, "heading_deg"),
                  b.Broadcast(valid, 1, "heading_valid"),
                  std::nullopt};
    const std::optional<DoubleArray> s = OptionalArray(sigma);
    if (s) g.sigma = b.Broadcast(*s, 3, "sigma_enu");
    return PushAll(b.n(), [&](py::ssize_t i) { return g.Make(i); });
  }

  py::object PushGnssVelocity(const DoubleArray& t, const DoubleArray& v, const py::object& sigma) {
    Batch b;
    GnssVelocityColumns g{b.Required(t, 1, "t"), b.Required(v, 3, "v_enu"), std::nullopt};
    const std::optional<DoubleArray> s = OptionalArray(sigma);
    if (s) g.sigma = b.Broadcast(*s, 3, "sigma_enu");
    return PushAll(b.n(), [&](py::ssize_t i) { return g.Make(i); });
  }

  uint64_t PushRecords(const py::object& log);

  void Finish() {
    Guard guard(this);
    py::gil_scoped_release release;
    session_->Finish();
  }

  py::dict Poll(std::optional<size_t> max_states) {
    Guard guard(this);
    std::map<api::Stream, StateColumns> streams;
    {
      py::gil_scoped_release release;
      api::State s;
      for (size_t n = 0; (!max_states || n < *max_states) && session_->Poll(&s); ++n) streams[s.stream].Add(s);
    }
    return TakeNumpy(&streams);
  }

  bool Initialized() {
    Guard guard(this);
    py::gil_scoped_release release;
    return session_->initialized();
  }
  bool InitTimedOut() {
    Guard guard(this);
    py::gil_scoped_release release;
    return session_->init_timed_out();
  }
  api::Status Status() {
    Guard guard(this);
    py::gil_scoped_release release;
    return session_->status();
  }
  std::string StatsJson() {
    Guard guard(this);
    py::gil_scoped_release release;
    return session_->StatsJson();
  }

 private:
  // One call at a time: the API's Session is not thread-safe, and a call from inside the state callback
  // would deadlock on the lock the callback runs under. Either is a UsageError instead.
  class Guard {
   public:
    explicit Guard(PySession* s) : s_(s) {
      if (s_->busy_.exchange(true)) {
        ThrowUsage("gins.Session: called while another call on it runs (from its state callback or another thread)");
      }
    }
    ~Guard() { s_->busy_ = false; }
    Guard(const Guard&) = delete;
    Guard& operator=(const Guard&) = delete;

   private:
    PySession* s_;
  };

  // n measurements (one when n < 0: returns a bool, else a bool array) made by make(i), pushed without the
  // GIL. An exception (a callback's, or the API's) stops at that record: those before it are taken.
  template <typename Make>
  py::object PushAll(py::ssize_t n, Make make) {
    Guard guard(this);
    pushed_ = true;
    if (n < 0) {
      bool taken;
      {
        py::gil_scoped_release release;
        taken = session_->Push(make(0));
      }
      return py::bool_(taken);
    }
    py::array_t<bool> taken(n);
    bool* out = taken.mutable_data();
    {
      py::gil_scoped_release release;
      for (py::ssize_t i = 0; i < n; ++i) {
        if ((i + 1) % kSignalCheckRecords == 0) RaisePendingSignals();  // Ctrl-C: those before i are taken
        out[i] = session_->Push(make(i));
      }
    }
    return std::move(taken);
  }

  std::unique_ptr<api::Session> session_;
  py::object callback_ = py::none();
  bool pushed_ = false;
  std::atomic<bool> busy_{false};
};

// push_records: the columns of a gins.read_log() result (or any mapping with its keys) merged into one
// sequence: in the order of their "line" numbers when every type has them (a log's own order, so the
// session sees what `gins run` gives it), else by time, equal times in the order IMU, wheel, GNSS, GNSS
// velocity (that of gins simulate's logs).
struct Entry {
  double t;
  uint64_t line;
  uint8_t type;  // 0 IMU, 1 wheel, 2 GNSS, 3 GNSS velocity, 4 a measurement module's
  py::ssize_t i;
};

py::object Get(const py::object& mapping, const char* key) {
  if (mapping.is_none()) return py::none();
  return mapping.attr("get")(key);
}

DoubleArray Need(const py::object& mapping, const char* type, const char* key) {
  const py::object o = Get(mapping, key);
  if (o.is_none()) throw py::key_error(std::string(type) + " records without '" + key + "'");
  return py::cast<DoubleArray>(o);
}

uint64_t PySession::PushRecords(const py::object& log) {
  static const double kZero = 0.0;
  const Column kNone{&kZero, 0};  // 0 for every record
  const char* kTypes[] = {"imu", "wheel", "gnss", "gnss_velocity"};
  py::object parts[4];
  for (int k = 0; k < 4; ++k) parts[k] = Get(log, kTypes[k]);
  // Every argument converted (and kept alive) before the GIL goes.
  std::vector<DoubleArray> keep;
  auto need = [&](int k, const char* key) -> const DoubleArray& {
    keep.push_back(Need(parts[k], kTypes[k], key));
    return keep.back();
  };
  keep.reserve(32);
  Column imu[3], wheel[3];
  GnssColumns gnss{};
  GnssVelocityColumns gnss_velocity{};
  py::ssize_t n[4] = {0, 0, 0, 0};
  std::vector<std::optional<py::array_t<uint64_t, py::array::c_style | py::array::forcecast>>> lines(4);
  for (int k = 0; k < 4; ++k) {
    if (parts[k].is_none()) continue;
    Batch b;
    switch (k) {
      case 0:
        imu[0] = b.Required(need(k, "t"), 1, "imu t");
        imu[1] = b.Required(need(k, "gyro"), 3, "imu gyro");
        imu[2] = b.Required(need(k, "acc"), 3, "imu acc");
        break;
      case 1:
        wheel[0] = b.Required(need(k, "t"), 1, "wheel t");
        wheel[1] = b.Required(need(k, "left_pulses"), 1, "wheel left_pulses");
        wheel[2] = b.Required(need(k, "right_pulses"), 1, "wheel right_pulses");
        break;
      case 2: {
        gnss.t = b.Required(need(k, "t"), 1, "gnss t");
        gnss.lat = b.Required(need(k, "lat_deg"), 1, "gnss lat_deg");
        gnss.lon = b.Required(need(k, "lon_deg"), 1, "gnss lon_deg");
        gnss.alt = b.Required(need(k, "alt_m"), 1, "gnss alt_m");
        // No dual-antenna heading unless given.
        gnss.heading =
            Get(parts[k], "heading_deg").is_none() ? kNone : b.Broadcast(need(k, "heading_deg"), 1, "gnss heading_deg");
        gnss.valid = Get(parts[k], "heading_valid").is_none()
                         ? kNone
                         : b.Broadcast(need(k, "heading_valid"), 1, "gnss heading_valid");
        if (!Get(parts[k], "sigma_enu").is_none()) gnss.sigma = b.Broadcast(need(k, "sigma_enu"), 3, "gnss sigma_enu");
        break;
      }
      case 3:
        gnss_velocity.t = b.Required(need(k, "t"), 1, "gnss_velocity t");
        gnss_velocity.v = b.Required(need(k, "v_enu"), 3, "gnss_velocity v_enu");
        if (!Get(parts[k], "sigma_enu").is_none()) {
          gnss_velocity.sigma = b.Broadcast(need(k, "sigma_enu"), 3, "gnss_velocity sigma_enu");
        }
        break;
    }
    if (b.n() < 0) throw py::value_error(std::string(kTypes[k]) + ": push_records takes arrays of records");
    n[k] = b.n();
    const py::object line = Get(parts[k], "line");
    if (!line.is_none()) {
      lines[k] = py::cast<py::array_t<uint64_t, py::array::c_style | py::array::forcecast>>(line);
      if (lines[k]->ndim() != 1 || lines[k]->shape(0) != n[k]) {
        throw py::value_error(std::string(kTypes[k]) + " line: one per record");
      }
    }
  }
  // A measurement module's records: read_log's entries under their token ("BARO": {"values", "line"}),
  // made into the API's OtherRecord while the GIL is held.
  std::vector<api::Record> others;
  bool others_by_line = true;
  for (const py::handle key : log.attr("keys")()) {
    if (!py::isinstance<py::str>(key)) continue;
    const std::string token = py::cast<std::string>(key);
    const bool is_token = !token.empty() && std::all_of(token.begin(), token.end(), [](char c) {
      return (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
    });
    if (!is_token) continue;
    const py::object part = log.attr("__getitem__")(key);
    const py::object values = Get(part, "values"), line = Get(part, "line");
    if (values.is_none()) throw py::key_error(token + " records without 'values'");
    const auto rows = py::cast<std::vector<std::vector<double>>>(values);
    std::vector<uint64_t> row_lines;
    if (!line.is_none()) row_lines = py::cast<std::vector<uint64_t>>(line);
    if (!line.is_none() && row_lines.size() != rows.size()) throw py::value_error(token + " line: one per record");
    others_by_line = others_by_line && (rows.empty() || !line.is_none());
    for (size_t i = 0; i < rows.size(); ++i) {
      api::Record r;
      r.type = api::Record::Type::kOther;
      r.other = {token, rows[i]};
      r.line = row_lines.empty() ? 0 : row_lines[i];
      others.push_back(std::move(r));
    }
  }
  bool by_line = others_by_line;
  for (int k = 0; k < 4; ++k) by_line = by_line && (n[k] == 0 || lines[k].has_value());
  const Column* times[4] = {&imu[0], &wheel[0], &gnss.t, &gnss_velocity.t};

  Guard guard(this);
  pushed_ = true;
  uint64_t taken = 0;
  {
    py::gil_scoped_release release;
    std::vector<Entry> order;
    order.reserve(static_cast<size_t>(n[0] + n[1] + n[2] + n[3]) + others.size());
    for (int k = 0; k < 4; ++k) {
      const uint64_t* l = lines[k] ? lines[k]->data() : nullptr;
      for (py::ssize_t i = 0; i < n[k]; ++i) {
        order.push_back({(*times[k])[i], l ? l[i] : 0, static_cast<uint8_t>(k), i});
      }
    }
    for (size_t i = 0; i < others.size(); ++i) {
      order.push_back({others[i].t(), others[i].line, 4, static_cast<py::ssize_t>(i)});
    }
    std::stable_sort(order.begin(), order.end(), [by_line](const Entry& a, const Entry& b) {
      if (by_line) return a.line < b.line;
      return a.t < b.t || (a.t == b.t && a.type < b.type);
    });
    uint64_t pushed = 0;
    for (const Entry& e : order) {
      if (++pushed % kSignalCheckRecords == 0) RaisePendingSignals();  // Ctrl-C: those before e are taken
      bool ok = false;
      switch (e.type) {
        case 0:
          ok = session_->Push(MakeImu(imu[0], imu[1], imu[2], e.i));
          break;
        case 1:
          ok = session_->Push(MakeWheel(wheel[0], wheel[1], wheel[2], e.i));
          break;
        case 2:
          ok = session_->Push(gnss.Make(e.i));
          break;
        case 3:
          ok = session_->Push(gnss_velocity.Make(e.i));
          break;
        case 4:
          ok = session_->Push(others[static_cast<size_t>(e.i)]);
          break;
      }
      taken += ok ? 1 : 0;
    }
  }
  return taken;
}

}  // namespace

void BindSession(py::module_& m) {
  py::class_<PySession>(m, "Session", "The push API (gins.Session wraps it).")
      .def(py::init<const api::Config&, const std::string&, bool, bool, size_t>(), "config"_a, "mode"_a = "eskf",
           "parallel"_a = false, "geodetic"_a = true, "max_queued_states"_a = 100000)
      .def("on_state", &PySession::OnState, "callback"_a,
           "Call callback(state: gins.State) for each state (None: queue them for poll()). Before the first push.")
      .def("push_imu", &PySession::PushImu, "t"_a, "gyro"_a, "acc"_a,
           "One IMU sample (t, 3, 3) or n of them (n, n×3, n×3): rad/s and m/s² in the IMU's axes. True (or a "
           "bool array) where taken.")
      .def("push_wheel", &PySession::PushWheel, "t"_a, "left_pulses"_a, "right_pulses"_a,
           "One ODOM record or n: pulses counted over (t - wheel.interval_s, t].")
      .def("push_gnss", &PySession::PushGnss, "t"_a, "lat_deg"_a, "lon_deg"_a, "alt_m"_a, "heading_deg"_a = 0.0,
           "heading_valid"_a = false, "sigma_enu"_a = py::none(),
           "One GNSS fix or n; heading_deg/heading_valid/sigma_enu may be one value for all; a NaN σ row: none.")
      .def("push_gnss_velocity", &PySession::PushGnssVelocity, "t"_a, "v_enu"_a, "sigma_enu"_a = py::none(),
           "One GVEL record or n: ENU velocity, m/s.")
      .def("push_records", &PySession::PushRecords, "log"_a,
           "Every record of a gins.read_log() result, in the log's order; returns how many were taken.")
      .def("finish", &PySession::Finish, "End of the data: the estimators flush (the smoother its window).")
      .def("_poll", &PySession::Poll, "max_states"_a = py::none())
      .def("initialized", &PySession::Initialized)
      .def("init_timed_out", &PySession::InitTimedOut)
      .def("status", &PySession::Status, "Counts, origin and every rejection (gins::api::Status).")
      .def("_stats_json", &PySession::StatsJson);
}

}  // namespace gins::python
