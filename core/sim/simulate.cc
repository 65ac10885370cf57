// Simulate: a simulated drive written to log.txt and truth.csv (core/sim/simulator.h).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "core/io/trajectory_writer.h"
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

void WriteGnss(const GnssRecord& g, AtomicFile* log) {
  CheckedPrintf(log, std::fprintf(log->stream(), "GNSS %.6f %.10f %.10f %.4f %.5f %d", g.t, g.lat_deg, g.lon_deg,
                                  g.alt_m, g.heading_deg, g.heading_valid ? 1 : 0));
  if (g.has_sigma) {
    CheckedPrintf(log, std::fprintf(log->stream(), " %.4f %.4f %.4f", g.sigma_enu.x(), g.sigma_enu.y(),
                                    g.sigma_enu.z()));
  }
  CheckedPrintf(log, std::fputs("\n", log->stream()));
}

void WriteRecord(const Simulator& simulator, const SimRecord& r, AtomicFile* log, AtomicFile* truth,
                 SimulationResult* result) {
  switch (r.type) {
    case SimRecord::Type::kImu: {
      const ImuSample& m = r.imu;
      CheckedPrintf(log, std::fprintf(log->stream(), "IMU %.6f %.9e %.9e %.9e %.9e %.9e %.9e\n", m.t, m.gyro.x(),
                                      m.gyro.y(), m.gyro.z(), m.acc.x(), m.acc.y(), m.acc.z()));
      WriteTruthRow(simulator, r.truth, truth);
      ++result->imu;
      break;
    }
    case SimRecord::Type::kWheel:
      // Whole pulses, printed as integers (a rounded −0.4 would print as "-0" with %.0f).
      CheckedPrintf(log, std::fprintf(log->stream(), "ODOM %.6f %lld %lld\n", r.wheel.t,
                                      std::llround(r.wheel.left_pulses), std::llround(r.wheel.right_pulses)));
      ++result->wheel;
      break;
    case SimRecord::Type::kGnss:
      WriteGnss(r.gnss, log);
      ++result->gnss;
      break;
    case SimRecord::Type::kGnssVelocity: {
      const GnssVelocityRecord& g = r.gnss_velocity;
      CheckedPrintf(log, std::fprintf(log->stream(), "GVEL %.6f %.4f %.4f %.4f %.4f %.4f %.4f\n", g.t, g.v_enu.x(),
                                      g.v_enu.y(), g.v_enu.z(), g.sigma_enu.x(), g.sigma_enu.y(), g.sigma_enu.z()));
      ++result->gnss_velocity;
      break;
    }
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
  AtomicFile log(log_path);
  AtomicFile truth(truth_path);

  WriteLogHeader(sim, simulator, &log);
  truth.Write("t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu\n");
  SimulationResult result;
  result.duration = simulator.truth().duration();
  SimRecord r;
  while (simulator.Next(&r)) WriteRecord(simulator, r, &log, &truth, &result);
  // Both files or neither: a truth without its log (or the reverse) would mislead.
  truth.Commit();
  try {
    log.Commit();
  } catch (...) {
    std::remove(truth_path.c_str());
    throw;
  }
  return result;
}

}  // namespace gins
