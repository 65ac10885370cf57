#include "core/io/geo_export.h"

#include <zlib.h>

#include <cmath>
#include <memory>

#include "core/io/log_reader.h"
#include "core/io/number_format.h"
#include "core/io/trajectory_writer.h"
#include "core/io/truth_reader.h"

namespace gins {
namespace {

// The first line that is not blank (without its line end), "" for an empty file.
std::string FirstLine(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (f == nullptr) throw InputError(path + ": cannot open");
  char buf[4096];
  std::string line;
  while (gzgets(f, buf, sizeof(buf)) != nullptr) {
    line = buf;
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    if (line.find_first_not_of(" \t") != std::string::npos) break;
    line.clear();
  }
  gzclose(f);
  return line;
}

bool StartsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

// A geodetic track CSV: t, lat, lon, height and, when its header names them, the σ east, north, up.
ExportSource ReadGeodeticCsv(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (f == nullptr) throw InputError(path + ": cannot open");
  std::unique_ptr<gzFile_s, int (*)(gzFile)> close(f, gzclose);
  ExportSource src;
  src.kind = "lla";
  src.has_attitude = false;
  std::optional<LocalEnuFrame> frame;
  char buf[4096];
  uint64_t line_no = 0;
  size_t columns = 0;
  while (gzgets(f, buf, sizeof(buf)) != nullptr) {
    ++line_no;
    std::string line(buf);
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    if (columns == 0) {  // the header
      columns = 1;
      for (char c : line) columns += c == ',';
      src.trajectory.has_sigma = columns >= 7;
      continue;
    }
    double v[7] = {};
    const char* p = line.c_str();
    const char* end = p + line.size();
    size_t n = 0;
    while (n < columns && n < 7) {
      const char* stop = nullptr;
      v[n] = ParseDouble(p, end, &stop);
      if (stop == p || !std::isfinite(v[n])) break;
      ++n;
      p = stop;
      if (p < end && *p == ',') ++p;
    }
    if (n != std::min<size_t>(columns, 7) || p != end) {
      throw InputError(path + ":" + std::to_string(line_no) + ": expected " + std::to_string(columns) +
                       " numbers separated by commas");
    }
    if (!IsPlausibleGeodetic(v[1], v[2], v[3])) {
      throw InputError(path + ":" + std::to_string(line_no) + ": latitude, longitude or height out of range");
    }
    auto& samples = src.trajectory.samples;
    if (!samples.empty() && v[0] <= samples.back().t) {
      throw InputError(path + ":" + std::to_string(line_no) + ": time does not increase");
    }
    const GeodeticPoint g{v[1], v[2], v[3]};
    if (!frame) {
      frame.emplace(g);
      src.trajectory.origin = g;
    }
    TrajectorySample s;
    s.t = v[0];
    s.p_w = frame->ToEnu(g);
    s.yaw_known = false;
    if (src.trajectory.has_sigma) s.sigma_p = Vec3(v[4], v[5], v[6]);
    samples.push_back(s);
  }
  if (src.trajectory.samples.empty()) throw InputError(path + ": no rows");
  src.trajectory.path = path;
  return src;
}

ExportSource ReadTruthSource(const std::string& path) {
  // Read in a frame at the Earth's (0, 0, 0), exact anywhere, then moved to one at the first row.
  const LocalEnuFrame provisional(GeodeticPoint{0.0, 0.0, 0.0});
  ExportSource src;
  src.kind = "truth";
  src.trajectory.path = path;
  src.trajectory.mode = "truth";
  src.trajectory.has_velocity = true;
  src.trajectory.samples = ToTrajectorySamples(ReadTruth(path, provisional));
  src.trajectory.origin = provisional.origin();
  const LocalEnuFrame first(provisional.ToGeodetic(src.trajectory.samples.front().p_w));
  ChangeFrame(provisional, first, &src.trajectory);
  return src;
}

}  // namespace

ExportSource ReadExportSource(const std::string& path, const std::optional<GeodeticPoint>& origin) {
  const std::string first = FirstLine(path);
  if (StartsWith(first, "t,lat,lon,alt")) return ReadTruthSource(path);
  if (StartsWith(first, "t,lat_deg,lon_deg,height_m")) return ReadGeodeticCsv(path);
  ExportSource src;
  src.trajectory = ReadTrajectory(path);
  src.kind = first.find("px") != std::string::npos && first[0] != '#' ? "states" : "tum";
  if (!src.trajectory.origin) {
    if (!origin) {
      throw InputError(path + ": no origin (a foreign TUM file, or a states CSV without its TUM file beside "
                              "it): give --origin LAT,LON,HEIGHT");
    }
    src.trajectory.origin = origin;
  }
  return src;
}

GeoSample ToGeoSample(const LocalEnuFrame& frame, const TrajectorySample& s, const SampleContent& content) {
  GeoSample g;
  g.t = s.t;
  const GeodeticPoint p = frame.ToGeodetic(s.p_w);
  g.lat_deg = p.lat_deg;
  g.lon_deg = p.lon_deg;
  g.height_m = p.alt_m;
  // Velocity and heading against the local north at the point, not the frame's (they differ by the
  // meridian convergence, 0.01° at 1 km).
  const Mat3 R_l_w = frame.RotationFromLocalEnu(p).transpose();
  if (content.velocity) g.v_enu = R_l_w * s.v_w;
  if (content.attitude && s.yaw_known) {
    const Vec3 x_l = R_l_w * (s.q_wb * Vec3::UnitX());
    double heading = std::atan2(x_l.x(), x_l.y()) * 180.0 / M_PI;
    if (heading < 0.0) heading += 360.0;
    g.heading_deg = heading;
  }
  if (content.sigma) g.sigma_enu = s.sigma_p;
  return g;
}

GeoTrack ToGeoTrack(const ExportSource& source, const std::string& name) {
  const Trajectory& traj = source.trajectory;
  const LocalEnuFrame frame(*traj.origin);
  const SampleContent content{traj.has_velocity, source.has_attitude, traj.has_sigma};
  GeoTrack track;
  track.name = name;
  track.samples.reserve(traj.samples.size());
  for (const TrajectorySample& s : traj.samples) track.samples.push_back(ToGeoSample(frame, s, content));
  return track;
}

void WriteGeodeticCsv(const GeoTrack& track, std::FILE* out) {
  const bool sigma = !track.samples.empty() && track.samples.front().sigma_enu.has_value();
  std::fputs(sigma ? kGeodeticCsvColumns : "t,lat_deg,lon_deg,height_m\n", out);
  for (const GeoSample& s : track.samples) {
    std::fprintf(out, "%.6f,%.9f,%.9f,%.4f", s.t, s.lat_deg, s.lon_deg, s.height_m);
    if (sigma) std::fprintf(out, ",%.4e,%.4e,%.4e", s.sigma_enu->x(), s.sigma_enu->y(), s.sigma_enu->z());
    std::fputc('\n', out);
  }
}

void WriteTumInFrame(const ExportSource& source, const GeodeticPoint& origin, std::FILE* out) {
  if (!source.has_attitude) {
    throw InputError(source.trajectory.path + ": a geodetic track has no attitude: TUM needs one");
  }
  Trajectory traj = source.trajectory;
  ChangeFrame(LocalEnuFrame(*traj.origin), LocalEnuFrame(origin), &traj);
  std::fputs(TrajectoryHeader(traj.mode.empty() ? source.kind : traj.mode, origin).c_str(), out);
  for (const TrajectorySample& s : traj.samples) {
    NavState x;
    x.t = s.t;
    x.p_wb = s.p_w;
    x.q_wb = s.q_wb;
    WriteTumLine(out, x);
  }
}

NmeaQuality QualityOf(const std::vector<GeoInterval>& no_fix, const GeoSample& s) {
  for (const GeoInterval& i : no_fix) {
    if (s.t >= i.t0 && s.t <= i.t1) return NmeaQuality::kDeadReckoning;
  }
  if (!s.sigma_enu) return NmeaQuality::kGps;
  const double sigma_h = std::hypot(s.sigma_enu->x(), s.sigma_enu->y());
  return sigma_h <= 0.05 ? NmeaQuality::kRtkFixed : sigma_h <= 0.5 ? NmeaQuality::kRtkFloat : NmeaQuality::kGps;
}

bool OnNmeaGrid(double t, double rate_hz, double* next_t) {
  if (rate_hz <= 0.0) return true;
  // A microsecond of slack: the outputs' times are printed to 6 decimals.
  if (t < *next_t - 1e-6) return false;
  *next_t = (std::floor(t * rate_hz + 1e-6) + 1.0) / rate_hz;
  return true;
}

void WriteNmea(const GeoTrack& track, const NmeaExportOptions& options, std::FILE* out) {
  double next_t = -1e300;
  for (const GeoSample& s : track.samples) {
    if (!HasDate(s.t)) {
      throw InputError(track.name + ": a state at t = " + std::to_string(s.t) +
                       " s, not an absolute time: NMEA needs the UTC date and time (docs/formats.md §2.6)");
    }
    if (OnNmeaGrid(s.t, options.rate_hz, &next_t)) WriteNmeaEpoch(s, QualityOf(track.no_fix, s), options, out);
  }
}

void WriteNmeaEpoch(const GeoSample& s, NmeaQuality quality, const NmeaExportOptions& options, std::FILE* out) {
  NmeaEpoch e;
  e.unix_utc = LogTimeToUnixUtc(s.t, options.time_scale);
  e.sample = s;
  e.quality = quality;
  std::fputs(NmeaGga(e).c_str(), out);
  std::fputs(NmeaRmc(e).c_str(), out);
  if (options.gst) std::fputs(NmeaGst(e).c_str(), out);
  if (options.hdt) std::fputs(NmeaHdt(e).c_str(), out);
}

}  // namespace gins
