// Simulate: a simulated drive written to log.txt and truth.csv (core/sim/simulator.h).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <variant>

#include <GeographicLib/Geocentric.hpp>

#include "core/io/rinex.h"
#include "core/io/trajectory_writer.h"
#include "core/sim/raw_gnss.h"
#include "core/sim/simulator.h"

namespace gins {
namespace {

void CheckedPrintf(AtomicFile* file, int result) {
  if (result < 0) throw std::runtime_error(file->path() + ": write failed");
}

// The two comment lines that open the log: the drive's settings and the record formats. Settings at their
// defaults are left out, so a log of a default set-up reads as before they existed.
void WriteLogHeader(const SimOptions& sim, const Simulator& simulator, AtomicFile* log) {
  const GeodeticPoint& o = sim.origin;
  CheckedPrintf(log, std::fprintf(log->stream(),
                                  "# gins simulate seed=%u start_time=%.6f duration=%.6f origin_lla=%.10f %.10f %.4f "
                                  "imu_rate=%g gnss_rate=%g wheel_rate=%g wheel_radius=%g pulses_per_rev=%g",
                                  sim.seed, sim.start_time, simulator.truth().duration(), o.lat_deg, o.lon_deg,
                                  o.alt_m, sim.imu_rate, sim.gnss_rate, sim.wheel_rate, sim.wheel_radius,
                                  sim.pulses_per_rev));
  if (sim.earth_rotation) CheckedPrintf(log, std::fputs(" earth_rotation=1", log->stream()));
  if (sim.log_start > 0.0) CheckedPrintf(log, std::fprintf(log->stream(), " log_start=%g", sim.log_start));
  if (sim.gnss_noise_correlation > 0.0) {
    CheckedPrintf(log, std::fprintf(log->stream(), " gnss_noise_correlation=%g", sim.gnss_noise_correlation));
  }
  const bool gnss_velocity = (sim.gnss_velocity_sigma.array() > 0.0).any();
  CheckedPrintf(log, std::fprintf(log->stream(), "\n# IMU t gx gy gz ax ay az | ODOM t left right | GNSS t lat lon "
                                                 "alt heading valid%s%s\n",
                                  sim.write_gnss_sigma ? " se sn su" : "", gnss_velocity ? " | GVEL t ve vn vu se sn su" : ""));
}

// A truth row (docs/formats.md §4): attitude and velocity in the local ENU frame at the row's point, which is w for
// the flat model (whose world has one vertical).
void WriteTruthRow(const Simulator& simulator, const NavState& x, AtomicFile* truth) {
  const GeodeticPoint g = simulator.truth().frame().ToGeodetic(x.p_wb);
  Quat q = x.q_wb;
  Vec3 v = x.v_w;
  if (simulator.options().earth_rotation) {
    const Mat3 R_l_w = simulator.truth().frame().RotationFromLocalEnu(g).transpose();
    q = (Quat(R_l_w) * x.q_wb).normalized();
    v = R_l_w * x.v_w;
  }
  CheckedPrintf(truth, std::fprintf(truth->stream(), "%.6f,%.10f,%.10f,%.4f,%.9f,%.9f,%.9f,%.9f,%.6f,%.6f,%.6f\n",
                                    x.t, g.lat_deg, g.lon_deg, g.alt_m, q.w(), q.x(), q.y(), q.z(), v.x(), v.y(),
                                    v.z()));
}

// A record's log line, at the simulator's own precision.
void WriteLine(const ImuSample& m, AtomicFile* log) {
  CheckedPrintf(log, std::fprintf(log->stream(), "IMU %.6f %.9e %.9e %.9e %.9e %.9e %.9e\n", m.t, m.gyro.x(),
                                  m.gyro.y(), m.gyro.z(), m.acc.x(), m.acc.y(), m.acc.z()));
}

void WriteLine(const WheelRecord& w, AtomicFile* log) {
  // Whole pulses, printed as integers (a rounded −0.4 would print as "-0" with %.0f).
  CheckedPrintf(log, std::fprintf(log->stream(), "ODOM %.6f %lld %lld\n", w.t, std::llround(w.left_pulses),
                                  std::llround(w.right_pulses)));
}

void WriteLine(const GnssRecord& g, AtomicFile* log) {
  CheckedPrintf(log, std::fprintf(log->stream(), "GNSS %.6f %.10f %.10f %.4f %.5f %d", g.t, g.lat_deg, g.lon_deg,
                                  g.alt_m, g.heading_deg, g.heading_valid ? 1 : 0));
  if (g.has_sigma) {
    CheckedPrintf(log, std::fprintf(log->stream(), " %.4f %.4f %.4f", g.sigma_enu.x(), g.sigma_enu.y(),
                                    g.sigma_enu.z()));
  }
  CheckedPrintf(log, std::fputs("\n", log->stream()));
}

void WriteLine(const GnssVelocityRecord& g, AtomicFile* log) {
  CheckedPrintf(log, std::fprintf(log->stream(), "GVEL %.6f %.4f %.4f %.4f %.4f %.4f %.4f\n", g.t, g.v_enu.x(),
                                  g.v_enu.y(), g.v_enu.z(), g.sigma_enu.x(), g.sigma_enu.y(), g.sigma_enu.z()));
}

// A measurement module's record (core/measurement_module.h): its token and numbers, 9 decimals.
template <typename R>
void WriteLine(const R& r, AtomicFile* log) {
  double v[RecordTraits<R>::kInfo.max_fields];
  const size_t n = R::Values(r, v);
  CheckedPrintf(log, std::fprintf(log->stream(), "%s %.6f", RecordTraits<R>::kInfo.token, v[0]));
  for (size_t i = 1; i < n; ++i) CheckedPrintf(log, std::fprintf(log->stream(), " %.9f", v[i]));
  CheckedPrintf(log, std::fputs("\n", log->stream()));
}

void WriteRecord(const Simulator& simulator, const SimRecord& r, AtomicFile* log, AtomicFile* truth,
                 SimulationResult* result) {
  std::visit([log](const auto& m) { WriteLine(m, log); }, r.data);
  if (r.is<ImuSample>()) WriteTruthRow(simulator, r.truth, truth);
  ++result->records[r.type_index()];
}

// obs.rnx: the raw observations of the antenna over the logged span (core/sim/raw_gnss.h). w is the local ENU
// frame at the origin fixed to the Earth (LocalEnuFrame, GeographicLib's LocalCartesian), so
// r_ecef = r0_ecef + R_ecef_w·p_w exactly, and velocities in w turn by R_ecef_w alone.
uint64_t WriteRawGnss(const SimOptions& sim, const TruthTrajectory& truth, const std::string& path) {
  const RawGnssSimConfig& config = sim.raw_gnss;
  if (config.nav_file.empty()) {
    throw std::invalid_argument("simulate.raw_gnss_nav_file: required when raw_gnss_enabled is true");
  }
  const RinexNav nav = ReadRinexNav(config.nav_file, InputOptions{});
  RawGnssSimOptions options = config.options;
  options.signals = RawGnssSignalsFromText(config);
  for (const RinexIonoCorrection& c : nav.header.iono) {  // the file's broadcast ionosphere is the truth's
    if (c.type == "GPSA") options.klobuchar_alpha = c.params;
    if (c.type == "GPSB") options.klobuchar_beta = c.params;
  }
  // Its own seed, drawn from the master past the sensors' streams (simulator.cc uses indices 0..7).
  std::mt19937_64 master(sim.seed);
  master.discard(16);
  RawGnssSimulator raw(nav.kepler, options, master());
  const GeodeticPoint& o = sim.origin;
  Vec3 r0_ecef;
  std::vector<double> m(9);
  GeographicLib::Geocentric::WGS84().Forward(o.lat_deg, o.lon_deg, o.alt_m, r0_ecef.x(), r0_ecef.y(), r0_ecef.z(),
                                             m);
  Mat3 R_ecef_w;
  R_ecef_w << m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8];  // row-major, ENU to ECEF
  auto antenna = [&](double gps_s) {
    const TruthState x = truth.At(std::min(gps_s, truth.end_time()));
    const Mat3 R_wb = x.q_wb.toRotationMatrix();
    const Vec3 p_w = x.p_wb + R_wb * sim.lever_b;
    const Vec3 v_w = x.v_w + R_wb * x.omega_b.cross(sim.lever_b);
    return RawGnssTruth{gps_s, r0_ecef + R_ecef_w * p_w, R_ecef_w * v_w};
  };
  RawGnssFileOptions file;
  file.start_gps_s = truth.start_time() + sim.log_start;
  file.end_gps_s = truth.end_time();
  file.rate_hz = config.rate_hz;
  return WriteSimulatedRinexObs(path, &raw, file, antenna);
}

void WriteLogAndTruth(const SimOptions& sim, Simulator& simulator, const std::string& log_path,
                      const std::string& truth_path, SimulationResult* result) {
  AtomicFile log(log_path);
  AtomicFile truth(truth_path);

  WriteLogHeader(sim, simulator, &log);
  truth.Write("t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu\n");
  result->duration = simulator.truth().duration();
  SimRecord r;
  while (simulator.Next(&r)) WriteRecord(simulator, r, &log, &truth, result);
  // Both files or neither: a truth without its log (or the reverse) would mislead.
  truth.Commit();
  try {
    log.Commit();
  } catch (...) {
    std::remove(truth_path.c_str());
    throw;
  }
}

}  // namespace

SimulationResult Simulate(const SimOptions& sim, const std::string& out_dir) {
  Simulator simulator(sim);  // validates before any file is touched
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec || !std::filesystem::is_directory(out_dir)) {
    throw std::runtime_error(out_dir + ": cannot create output directory" + (ec ? ": " + ec.message() : ""));
  }
  const std::string log_path = (std::filesystem::path(out_dir) / "log.txt").string();
  const std::string truth_path = (std::filesystem::path(out_dir) / "truth.csv").string();
  const std::string obs_path = (std::filesystem::path(out_dir) / "obs.rnx").string();
  SimulationResult result;
  if (sim.raw_gnss.enabled) result.raw_gnss_epochs = WriteRawGnss(sim, simulator.truth(), obs_path);
  try {
    WriteLogAndTruth(sim, simulator, log_path, truth_path, &result);
  } catch (...) {
    if (sim.raw_gnss.enabled) std::remove(obs_path.c_str());  // all the files or none
    throw;
  }
  return result;
}

}  // namespace gins
