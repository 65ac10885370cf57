#include "apps/convert_command.h"

#include <cstdio>
#include <exception>
#include <tuple>

#include "core/io/gnss_convert.h"
#include "core/io/i2nav.h"

namespace gins {
namespace {

constexpr const char* kFooter =
    "Format i2nav (the text files of KF-GINS and OB_GINS, i2Nav group, Wuhan University):\n"
    "  --imu   t dθx dθy dθz dvx dvy dvz: GPS seconds of week; angle (rad) and velocity (m/s) increments over\n"
    "          (t_prev, t]; axes forward-right-down. Written as IMU rates in FLU stamped at the middle of\n"
    "          each interval (the rate is the increment over the actual interval).\n"
    "  --gnss  t lat lon h σn σe σv (deg, deg, m, 1-σ in m), or 13 columns with σ in columns 8-10. Written\n"
    "          as GNSS records with σ east north up and heading_valid 0.\n"
    "  Times are kept as in the files (both must share a time base). Columns may be split by spaces, tabs\n"
    "  or commas; '#' and '%' lines are comments; .gz inputs are read. Odometer data is not converted (no\n"
    "  documented i2Nav odometer file). Damaged lines are skipped and counted (--on-error skip) or stop the\n"
    "  conversion (stop); files whose columns are not what the format says are refused.\n"
    "\n"
    "Formats rtklib-pos, nmea, csv (GNSS merged with the IMU/wheel records of --imu; docs/formats.md §6):\n"
    "  --imu LOG  a gins log: its IMU and ODOM records are kept, its own GNSS/GVEL dropped; with\n"
    "             --imu-columns MAP it is a CSV of IMU samples. --wheel CSV --wheel-columns MAP adds wheels.\n"
    "  rtklib-pos RTKLIB .pos (rnx2rtkp, rtkpost): GPST/UTC/JST, calendar or week/seconds times; lat/lon/height\n"
    "             or x/y/z-ecef; Q 1 fix 2 float 3 sbas 4 dgps 5 single 6 ppp kept with their σ (sdn sde sdu,\n"
    "             or ECEF σ rotated to ENU); velocity columns (out-outvel) as GVEL.\n"
    "  nmea       GGA (+ geoid separation = ellipsoidal height), RMC/ZDA date, GST σ or HDOP × a per-quality\n"
    "             σ (fix 0.01, float 0.25, dgps 0.5, sbas 1, single 2 m; up twice that), RMC/VTG speed and\n"
    "             course as GVEL (vu 0), HDT/THS heading; UTC + leap seconds = GPS time; checksums required.\n"
    "  csv        --gnss-columns MAP, e.g. \"t=1,lat=2,lon=3,h=4,se=5,sn=6,su=7\" (1-based columns or header\n"
    "             names; :unit; a leading '-' negates: gy=-3 for FRD data).\n"
    "  Times go onto the log's clock (--time-scale gps: GPS seconds since 1980-01-06, or unix).";

}  // namespace

CLI::App* AddConvertCommand(CLI::App& app, ConvertRequest* req) {
  auto* convert = app.add_subcommand("convert", "Convert logs in other formats into a gins log");
  convert->footer(kFooter);
  convert->add_option("--format", req->format, "Input format")
      ->required()
      ->check(CLI::IsMember({"i2nav", "rtklib-pos", "nmea", "csv"}));
  convert
      ->add_option("--imu", req->imu_path,
                   "IMU file (i2nav); a gins log with the IMU/wheel records, or a CSV with --imu-columns "
                   "(rtklib-pos, nmea, csv)")
      ->required();
  convert->add_option("--gnss", req->gnss_path, "GNSS file (plain or .gz)")->required();
  convert->add_option("--out", req->out_path, "gins log to write (gzip if the name ends in .gz)")->required();
  convert
      ->add_option("--imu-data", req->imu_data,
                   "i2nav: what the IMU file's six data columns hold: increments (rad, m/s: the i2Nav format) "
                   "or rates (rad/s, m/s², same axes and columns)")
      ->check(CLI::IsMember({"increments", "rates"}))
      ->capture_default_str();
  convert
      ->add_option("--time-scale", req->time_scale,
                   "The log's clock: gps (GPS seconds since 1980-01-06, as the IMU log's) or unix (Unix UTC)")
      ->check(CLI::IsMember({"gps", "unix"}))
      ->capture_default_str();
  convert
      ->add_option("--min-quality", req->min_quality,
                   "Drop solutions worse than this: fix > float > ppp > dgps > sbas > single")
      ->check(CLI::IsMember({"fix", "float", "ppp", "dgps", "sbas", "single"}))
      ->capture_default_str();
  convert->add_option("--date", req->date, "nmea: UTC date YYYY-MM-DD of the first epoch, for files without RMC/ZDA");
  convert->add_option("--velocity-sigma", req->velocity_sigma, "nmea: GVEL horizontal 1-σ per axis, m/s")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  convert->add_option("--gnss-columns", req->gnss_columns, "csv: the GNSS file's column map");
  convert->add_option("--imu-columns", req->imu_columns,
                      "The --imu file is a CSV with this column map, e.g. \"t=1,gx=2,gy=3,gz=4,ax=5,ay=6,az=7\"");
  convert->add_option("--wheel", req->wheel_path, "A CSV of wheel pulses (with --wheel-columns)");
  convert->add_option("--wheel-columns", req->wheel_columns,
                      "The --wheel file's column map, e.g. \"t=1,left=2,right=3\"");
  convert->add_option("--on-error", req->on_error, "Damaged lines: skip (count them) or stop at the first")
      ->check(CLI::IsMember({"skip", "stop"}))
      ->capture_default_str();
  convert->add_option("--max-errors", req->max_errors, "With skip: give up after this many damaged lines per file")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  convert->add_option("--max-line-length", req->max_line_length, "Characters; a longer line is damage")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  return convert;
}

namespace {

// The options that belong to other formats than the one asked for: a usage error, not silently ignored.
std::string Misplaced(const ConvertRequest& r) {
  const bool i2nav = r.format == "i2nav";
  if (!i2nav && r.imu_data != "increments") return "--imu-data is for --format i2nav";
  if (i2nav && (r.time_scale != "gps" || r.min_quality != "single" || !r.date.empty() || !r.gnss_columns.empty() ||
                !r.imu_columns.empty() || !r.wheel_path.empty() || !r.wheel_columns.empty())) {
    return "--time-scale, --min-quality, --date, --*-columns and --wheel are not for --format i2nav";
  }
  if (r.format != "nmea" && !r.date.empty()) return "--date is for --format nmea";
  if (r.format != "nmea" && r.velocity_sigma != ConvertRequest().velocity_sigma) {
    return "--velocity-sigma is for --format nmea";
  }
  if (r.format != "csv" && !r.gnss_columns.empty()) return "--gnss-columns is for --format csv";
  if (r.format == "csv" && r.gnss_columns.empty()) return "--format csv needs --gnss-columns";
  if (r.wheel_path.empty() != r.wheel_columns.empty()) return "--wheel and --wheel-columns go together";
  return {};
}

int RunI2nav(const ConvertRequest& req, const InputOptions& options) {
  I2navInputs inputs;
  inputs.imu_path = req.imu_path;
  inputs.gnss_path = req.gnss_path;
  inputs.imu_data = req.imu_data == "rates" ? I2navImuData::kRates : I2navImuData::kIncrements;
  const I2navConversion result = ConvertI2nav(inputs, options, req.out_path);
  std::fputs(FormatConversionSummary(result).c_str(), stdout);
  return 0;
}

int RunGnss(const ConvertRequest& req, const InputOptions& options) {
  GnssConvertInputs in;
  in.format = req.format;
  in.gnss_path = req.gnss_path;
  in.gnss_columns = req.gnss_columns;
  in.imu_path = req.imu_path;
  in.imu_columns = req.imu_columns;
  in.wheel_path = req.wheel_path;
  in.wheel_columns = req.wheel_columns;
  ParseLogTimeScale(req.time_scale, &in.options.time_scale);
  ParseFixQuality(req.min_quality, &in.options.min_quality);
  in.options.velocity_sigma_m_s = req.velocity_sigma;
  if (!req.date.empty()) {
    int y = 0, m = 0, d = 0;
    char tail = 0;
    if (std::sscanf(req.date.c_str(), "%4d-%2d-%2d%c", &y, &m, &d, &tail) != 3 ||
        !CalendarDays(y, m, d, &in.options.start_date_days)) {
      std::fprintf(stderr, "gins: error: --date %s is not a date YYYY-MM-DD from 1980-01-06 on\n", req.date.c_str());
      return 2;
    }
  }
  // A map that cannot be right is a usage error, found before any file is read.
  for (const auto& [map, kind, option] : {std::make_tuple(req.gnss_columns, CsvKind::kGnss, "--gnss-columns"),
                                          std::make_tuple(req.imu_columns, CsvKind::kImu, "--imu-columns"),
                                          std::make_tuple(req.wheel_columns, CsvKind::kWheel, "--wheel-columns")}) {
    try {
      if (!map.empty()) ParseColumnMap(map, kind, option);
    } catch (const InputError& e) {
      std::fprintf(stderr, "gins: error: %s\n", e.what());
      return 2;
    }
  }
  const GnssConversion result = ConvertGnss(in, options, req.out_path);
  std::fputs(FormatGnssConversionSummary(result).c_str(), stdout);
  return 0;
}

}  // namespace

int RunConvert(const ConvertRequest& req) {
  if (const std::string why = Misplaced(req); !why.empty()) {
    std::fprintf(stderr, "gins: error: %s\n", why.c_str());
    return 2;
  }
  InputOptions options;
  options.on_error = req.on_error == "stop" ? InputErrorPolicy::kStop : InputErrorPolicy::kSkip;
  options.max_errors = req.max_errors;
  options.max_line_length = req.max_line_length;
  try {
    return req.format == "i2nav" ? RunI2nav(req, options) : RunGnss(req, options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gins: error: %s\n", e.what());
    return 1;
  }
}

}  // namespace gins
