// gins._gins: the Python package's extension (docs/python.md). The public API (gins/gins.h) and, for whole
// runs, `gins run` itself (apps/run_command.h: Run, the same code and files as the command line), with the
// states an output holds also kept in memory as numpy columns. The GIL is released while gins estimates or
// reads; the pure-Python package gins (gins/__init__.py) builds the user-facing objects on these parts.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "apps/python/bindings.h"
#include "apps/run_command.h"
#include "core/geodesy.h"  // the world frame's conversion, as State::lla and the track files use it
#include "core/io/number_format.h"
#include "core/io/text_input.h"  // InputError: a truth or log that cannot be read, from Run
#include "gins/gins.h"
#include "solver/estimator_pipeline.h"  // RunError: a run that cannot give a trajectory, from Run

namespace gins::python {
namespace {

using namespace pybind11::literals;

// The exception classes, created once with the module (they live as long as the interpreter).
struct ErrorTypes {
  PyObject* base = nullptr;
  PyObject* config = nullptr;
  PyObject* input = nullptr;
  PyObject* no_solution = nullptr;
  PyObject* usage = nullptr;
};
ErrorTypes g_errors;

PyObject* NewError(py::module_& m, const char* name, PyObject* base, const char* doc) {
  const std::string qualified = std::string("gins.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, base, nullptr);
  if (type == nullptr) throw py::error_already_set();
  m.attr(name) = py::handle(type);  // the module holds a reference; ours is kept for the translator
  return type;
}

PyObject* ErrorType(api::Error::Kind kind) {
  switch (kind) {
    case api::Error::Kind::kConfig:
      return g_errors.config;
    case api::Error::Kind::kInput:
      return g_errors.input;
    case api::Error::Kind::kNoSolution:
      return g_errors.no_solution;
    case api::Error::Kind::kUsage:
      return g_errors.usage;
  }
  return g_errors.base;
}

// An error of `gins run` that is none of the kinds above: an output that cannot be written.
class OtherError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A temporary folder for a run without out=: Run writes its files there (the summary's comparison reads
// them back), and it is removed with everything in it.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "gins-run-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw OtherError(pattern + ": cannot create a temporary folder");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// gins.run's part: `gins run` (Run) with each written state also kept. Returns (streams, summary JSON text,
// files written); out_dir empty: into a temporary folder, removed after (no files listed).
py::tuple RunLog(const api::Config& config, const std::filesystem::path& log, const std::string& mode,
                 const std::optional<std::filesystem::path>& truth, const std::optional<std::filesystem::path>& out,
                 const std::string& config_path) {
  api::Mode parsed;
  if (!api::ParseMode(mode, &parsed)) {
    throw py::value_error("unknown mode '" + mode + "' (eskf, smoother, both, batch, all)");
  }
  std::optional<TempDir> temp;
  if (!out) temp.emplace();
  RunRequest request;
  request.log_path = log.string();
  request.out_dir = out ? out->string() : temp->path();
  request.mode = mode;
  request.config_path = config_path;
  if (truth) request.truth_path = truth->string();
  std::map<api::Stream, StateColumns> streams;
  // On Run's writer thread, one state at a time, after the file's line is written. Without lla: Run's
  // session has no geodetic states (its outputs are in ENU), and gins.Trajectory converts p when asked.
  request.on_output_state = [&streams](const api::State& s) {
    streams.try_emplace(s.stream, false).first->second.Add(s);
  };
  request.poll = RaisePendingSignals;  // Ctrl-C stops the run, nothing committed
  RunResult result;
  {
    py::gil_scoped_release release;
    try {
      result = Run(config, request);
    } catch (const api::Error&) {
      throw;
    } catch (const RunError&) {
      throw;
    } catch (const InputError&) {
      throw;
    } catch (const std::runtime_error& e) {
      throw OtherError(e.what());
    }
  }
  py::list outputs;
  if (out) {
    for (const std::string& f : result.outputs) outputs.append(f);
  }
  return py::make_tuple(TakeNumpy(&streams), result.summary.dump(), outputs);
}

// gins.read_log's part: a log's records as columns per type, with each record's line in the log.
py::dict ReadLog(const std::filesystem::path& path, const api::Config& config) {
  std::vector<double> imu_t, gyro, acc, wheel_t, left, right, gnss_t, lat, lon, alt, heading, heading_valid, gnss_sigma,
      gvel_t, gvel_v, gvel_sigma;
  std::vector<uint64_t> imu_line, wheel_line, gnss_line, gvel_line;
  std::map<std::string, std::pair<std::vector<std::vector<double>>, std::vector<uint64_t>>> others;
  api::ReadCounts counts;
  {
    py::gil_scoped_release release;
    api::LogReader reader(path.string(), config);
    const double nan = std::nan("");
    for (api::Record r; reader.Next(&r);) {
      switch (r.type) {
        case api::Record::Type::kImu:
          imu_t.push_back(r.imu.t);
          gyro.insert(gyro.end(), r.imu.gyro, r.imu.gyro + 3);
          acc.insert(acc.end(), r.imu.acc, r.imu.acc + 3);
          imu_line.push_back(r.line);
          break;
        case api::Record::Type::kWheel:
          wheel_t.push_back(r.wheel.t);
          left.push_back(r.wheel.left_pulses);
          right.push_back(r.wheel.right_pulses);
          wheel_line.push_back(r.line);
          break;
        case api::Record::Type::kGnss: {
          const api::Gnss& g = r.gnss;
          gnss_t.push_back(g.t);
          lat.push_back(g.lat_deg);
          lon.push_back(g.lon_deg);
          alt.push_back(g.alt_m);
          heading.push_back(g.heading_deg);
          heading_valid.push_back(g.heading_valid ? 1.0 : 0.0);
          for (double s : g.sigma_enu) gnss_sigma.push_back(g.has_sigma ? s : nan);
          gnss_line.push_back(r.line);
          break;
        }
        case api::Record::Type::kGnssVelocity: {
          const api::GnssVelocity& v = r.gnss_velocity;
          gvel_t.push_back(v.t);
          gvel_v.insert(gvel_v.end(), v.v_enu, v.v_enu + 3);
          for (double s : v.sigma_enu) gvel_sigma.push_back(v.has_sigma ? s : nan);
          gvel_line.push_back(r.line);
          break;
        }
        case api::Record::Type::kOther: {  // a measurement module's (BARO): by token, its numbers (t first)
          auto& [values, lines] = others[r.other.type];
          values.push_back(r.other.values);
          lines.push_back(r.line);
          break;
        }
      }
    }
    counts = reader.counts();
  }
  auto n = [](const std::vector<double>& t) { return static_cast<py::ssize_t>(t.size()); };
  py::dict log;
  const py::ssize_t ni = n(imu_t), nw = n(wheel_t), ng = n(gnss_t), nv = n(gvel_t);
  log["imu"] = py::dict("t"_a = ToNumpy(std::move(imu_t), {ni}), "gyro"_a = ToNumpy(std::move(gyro), {ni, 3}),
                        "acc"_a = ToNumpy(std::move(acc), {ni, 3}), "line"_a = ToNumpy(std::move(imu_line), {ni}));
  log["wheel"] =
      py::dict("t"_a = ToNumpy(std::move(wheel_t), {nw}), "left_pulses"_a = ToNumpy(std::move(left), {nw}),
               "right_pulses"_a = ToNumpy(std::move(right), {nw}), "line"_a = ToNumpy(std::move(wheel_line), {nw}));
  py::array valid = ToNumpy(std::move(heading_valid), {ng}).attr("astype")("bool");
  log["gnss"] =
      py::dict("t"_a = ToNumpy(std::move(gnss_t), {ng}), "lat_deg"_a = ToNumpy(std::move(lat), {ng}),
               "lon_deg"_a = ToNumpy(std::move(lon), {ng}), "alt_m"_a = ToNumpy(std::move(alt), {ng}),
               "heading_deg"_a = ToNumpy(std::move(heading), {ng}), "heading_valid"_a = valid,
               "sigma_enu"_a = ToNumpy(std::move(gnss_sigma), {ng, 3}), "line"_a = ToNumpy(std::move(gnss_line), {ng}));
  log["gnss_velocity"] =
      py::dict("t"_a = ToNumpy(std::move(gvel_t), {nv}), "v_enu"_a = ToNumpy(std::move(gvel_v), {nv, 3}),
               "sigma_enu"_a = ToNumpy(std::move(gvel_sigma), {nv, 3}), "line"_a = ToNumpy(std::move(gvel_line), {nv}));
  for (auto& [type, rows] : others) {  // "BARO": {"values": [[t, ...], ...], "line": [...]}
    py::list values;
    for (const std::vector<double>& v : rows.first) values.append(py::cast(v));
    log[py::str(type)] = py::dict("values"_a = values, "line"_a = py::cast(rows.second));
  }
  log["counts"] =
      py::dict("lines"_a = counts.lines, "imu"_a = counts.imu, "wheel"_a = counts.wheel, "gnss"_a = counts.gnss,
               "gnss_velocity"_a = counts.gnss_velocity, "skipped"_a = counts.skipped);
  return log;
}

// The output files' number formats (core/io/number_format.h), for the tests' bit-for-bit comparison of
// the in-memory states with the files: each value as `gins run` writes it.
std::vector<std::string> FormatValues(const DoubleArray& values, int precision, bool scientific) {
  if (precision < 0 || precision > 9) throw py::value_error("precision must be 0-9");
  std::vector<std::string> out;
  out.reserve(static_cast<size_t>(values.size()));
  const double* v = values.data();
  char buffer[64];
  for (py::ssize_t i = 0; i < values.size(); ++i) {
    char* end = scientific ? FormatScientific(buffer, buffer + sizeof buffer, v[i], precision)
                           : FormatFixed(buffer, buffer + sizeof buffer, v[i], precision);
    out.emplace_back(buffer, end);
  }
  return out;
}

// gins.Trajectory's lla: ENU positions in the frame at `origin` (latitude, longitude, height) to geodetic
// ones, the conversion State::lla is made with (LocalEnuFrame::ToGeodetic), bit for bit.
py::array_t<double> EnuToLla(const std::vector<double>& origin, const DoubleArray& p) {
  if (origin.size() != 3) throw py::value_error("origin: (lat_deg, lon_deg, alt_m)");
  const py::ssize_t n = Records(p, 3, "p");
  if (n < 0) throw py::value_error("p: an n×3 array");
  const LocalEnuFrame frame(GeodeticPoint{origin[0], origin[1], origin[2]});
  py::array_t<double> lla({n, py::ssize_t{3}});
  double* out = lla.mutable_data();
  const double* in = p.data();
  {
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n; ++i) {
      const GeodeticPoint g = frame.ToGeodetic(Vec3(in[3 * i], in[3 * i + 1], in[3 * i + 2]));
      out[3 * i] = g.lat_deg, out[3 * i + 1] = g.lon_deg, out[3 * i + 2] = g.alt_m;
    }
  }
  return lla;
}

py::array_t<double> Vec(const double* v, py::ssize_t n) { return py::array_t<double>(n, v); }

void BindState(py::module_& m) {
  py::class_<api::State>(m, "State", "One estimate, as the state callback gets it (docs/python.md).")
      .def_property_readonly(
          "stream", [](const api::State& s) { return api::StreamName(s.stream); },
          "'eskf', 'smoother', 'smoother_online', 'batch' or 'eskf_rts'")
      .def_readonly("t", &api::State::t, "time, s (the log's clock)")
      .def_property_readonly(
          "p", [](const api::State& s) { return Vec(s.p_enu, 3); }, "position in ENU, m")
      .def_property_readonly(
          "q",
          [](const api::State& s) {
            const double q[4] = {s.q_wb[1], s.q_wb[2], s.q_wb[3], s.q_wb[0]};
            return Vec(q, 4);
          },
          "q_wb as x, y, z, w (the TUM order)")
      .def_property_readonly(
          "v", [](const api::State& s) { return Vec(s.v_enu, 3); }, "velocity in ENU, m/s")
      .def_property_readonly(
          "lla", [](const api::State& s) { return Vec(s.lla, 3); },
          "latitude, longitude (deg), ellipsoidal height (m); NaN with geodetic=False")
      .def_property_readonly(
          "gyro_bias", [](const api::State& s) { return Vec(s.gyro_bias, 3); }, "rad/s")
      .def_property_readonly(
          "acc_bias", [](const api::State& s) { return Vec(s.acc_bias, 3); }, "m/s²")
      .def_property_readonly(
          "sigma_p", [](const api::State& s) { return Vec(s.sigma_p, 3); }, "1-σ of p, m")
      .def_property_readonly(
          "sigma_v", [](const api::State& s) { return Vec(s.sigma_v, 3); }, "1-σ of v, m/s")
      .def_property_readonly(
          "sigma_att", [](const api::State& s) { return Vec(s.sigma_att, 3); },
          "1-σ of the attitude about E, N, U, rad")
      .def_readonly("odom_scale", &api::State::odom_scale, "wheel odometer scale factor")
      .def(
          "heading_deg", [](const api::State& s) { return api::HeadingDeg(s); },
          "Compass heading of the body x axis, deg clockwise from north in [0, 360).")
      .def(
          "roll_pitch_yaw_deg",
          [](const api::State& s) {
            double rpy[3];
            api::RollPitchYawDeg(s, rpy);
            return py::make_tuple(rpy[0], rpy[1], rpy[2]);
          },
          "Roll, pitch, yaw (ZYX, deg; yaw counter-clockwise from east).")
      .def("__repr__", [](const api::State& s) {
        return "<gins.State " + std::string(api::StreamName(s.stream)) + " t=" + std::to_string(s.t) + ">";
      });
}

void BindStatus(py::module_& m) {
  py::class_<api::Rejection>(m, "Rejection", "One kind of measurement not used, and how often.")
      .def_readonly("source", &api::Rejection::source)
      .def_readonly("measurement", &api::Rejection::measurement)
      .def_readonly("reason", &api::Rejection::reason)
      .def_readonly("count", &api::Rejection::count)
      .def("__repr__", [](const api::Rejection& r) {
        return "<gins.Rejection " + r.source + "/" + r.measurement + "/" + r.reason + ": " + std::to_string(r.count) +
               ">";
      });
  py::class_<api::Status>(m, "Status", "Session.status(): the C++ gins::api::Status.")
      .def_readonly("initialized", &api::Status::initialized)
      .def_readonly("diagnosis", &api::Status::diagnosis)
      .def_readonly("init_timed_out", &api::Status::init_timed_out)
      .def_property_readonly(
          "origin",
          [](const api::Status& s) -> py::object {
            if (!s.origin) return py::none();
            return py::make_tuple(s.origin->lat_deg, s.origin->lon_deg, s.origin->alt_m);
          },
          "(lat_deg, lon_deg, alt_m) of the ENU frame, or None before it is known")
      .def_readonly("first_time", &api::Status::first_time)
      .def_readonly("last_time", &api::Status::last_time)
      .def_readonly("accepted", &api::Status::accepted)
      .def_readonly("reordered", &api::Status::reordered)
      .def_readonly("rejected", &api::Status::rejected)
      .def_readonly("states", &api::Status::states)
      .def_readonly("states_dropped", &api::Status::states_dropped)
      .def_readonly("callback_errors", &api::Status::callback_errors)
      .def_readonly("watchdog_resets", &api::Status::watchdog_resets)
      .def_readonly("rejections", &api::Status::rejections)
      .def("__repr__", [](const api::Status& s) {
        return "<gins.Status initialized=" + std::string(s.initialized ? "True" : "False") +
               " accepted=" + std::to_string(s.accepted) + " states=" + std::to_string(s.states) + ">";
      });
}

void BindConfig(py::module_& m) {
  py::class_<api::Config>(m, "Config",
                          "A loaded and validated config (every key of config/default.yaml). Config() is the "
                          "defaults.")
      .def(py::init<>())
      .def_static(
          "from_file", [](const std::filesystem::path& path) { return api::Config::FromFile(path.string()); }, "path"_a,
          "Load a YAML file; gins.ConfigError names the file, key and line.")
      .def_static("from_yaml", &api::Config::FromYaml, "text"_a, "name"_a = "<yaml>",
                  "Load YAML text; `name` stands for the file in messages.")
      .def("to_yaml", &api::Config::ToYaml, "The effective config, every key, in the users' units.")
      .def_property_readonly("reorder_window_s", &api::Config::reorder_window_s);
}

}  // namespace

void ThrowUsage(const std::string& what) { throw api::Error(api::Error::Kind::kUsage, what); }

void BindErrors(py::module_& m) {
  g_errors.base = NewError(m, "Error", PyExc_RuntimeError, "Every error gins reports; str() is the CLI's message.");
  g_errors.config =
      NewError(m, "ConfigError", g_errors.base, "The config does not load: names the file, key and line.");
  g_errors.input = NewError(m, "InputError", g_errors.base,
                            "A log or truth that cannot be read or is too damaged (input.*), or IMU data in wrong "
                            "units or axes (Session.push_*): names the file and line.");
  g_errors.no_solution = NewError(m, "NoSolutionError", g_errors.base,
                                  "The data give no trajectory: no usable IMU or GNSS records, never initialised, "
                                  "or (gins.run) IMU data in wrong units or axes.");
  g_errors.usage = NewError(m, "UsageError", g_errors.base, "The API called out of turn (e.g. a push after finish).");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const api::Error& e) {
      PyErr_SetString(ErrorType(e.kind()), e.what());
    } catch (const RunError& e) {
      PyErr_SetString(g_errors.no_solution, e.what());
    } catch (const InputError& e) {
      PyErr_SetString(g_errors.input, e.what());
    } catch (const OtherError& e) {
      PyErr_SetString(g_errors.base, e.what());
    }
  });
}

}  // namespace gins::python

PYBIND11_MODULE(_gins, m) {
  namespace py = pybind11;
  using namespace pybind11::literals;
  using namespace gins::python;
  m.doc() = "gins's extension: the public C++ API and `gins run` (use the package gins, not this module).";
  m.attr("__version__") = gins::api::Version();
  BindErrors(m);
  BindConfig(m);
  BindState(m);
  BindStatus(m);
  BindSession(m);
  m.def("run", &RunLog, "config"_a, "log"_a, "mode"_a, "truth"_a, "out"_a, "config_path"_a,
        "(streams, summary JSON, files): `gins run` with the written states kept (gins.run wraps it).");
  m.def("read_log", &ReadLog, "path"_a, "config"_a, "A log's records as numpy columns (gins.read_log wraps it).");
  m.def("_enu_to_lla", &EnuToLla, "origin"_a, "p"_a, "Geodetic positions of ENU ones (gins.Trajectory's lla).");
  m.def("_format", &FormatValues, "values"_a, "precision"_a, "scientific"_a = false,
        "Each value as the output files write it (tests).");
}
