#include "apps/convert_command.h"

#include <cstdio>
#include <exception>

#include "core/io/i2nav.h"

namespace gins {

CLI::App* AddConvertCommand(CLI::App& app, ConvertRequest* req) {
  auto* convert = app.add_subcommand("convert", "Convert logs in other formats into a gins log");
  convert->footer(
      "Format i2nav (the text files of KF-GINS and OB_GINS, i2Nav group, Wuhan University):\n"
      "  --imu   t dθx dθy dθz dvx dvy dvz: GPS seconds of week; angle (rad) and velocity (m/s) increments over\n"
      "          (t_prev, t]; axes forward-right-down. Written as IMU rates in FLU stamped at the middle of\n"
      "          each interval (the rate is the increment over the actual interval).\n"
      "  --gnss  t lat lon h σn σe σv (deg, deg, m, 1-σ in m), or 13 columns with σ in columns 8-10. Written\n"
      "          as GNSS records with σ east north up and heading_valid 0.\n"
      "  Times are kept as in the files (both must share a time base). Columns may be split by spaces, tabs\n"
      "  or commas; '#' and '%' lines are comments; .gz inputs are read. Odometer data is not converted (no\n"
      "  documented i2Nav odometer file). Damaged lines are skipped and counted (--on-error skip) or stop the\n"
      "  conversion (stop); files whose columns are not what the format says are refused.");
  convert->add_option("--format", req->format, "Input format")->required()->check(CLI::IsMember({"i2nav"}));
  convert->add_option("--imu", req->imu_path, "IMU file (plain or .gz)")->required();
  convert->add_option("--gnss", req->gnss_path, "GNSS position file (plain or .gz)")->required();
  convert->add_option("--out", req->out_path, "gins log to write (gzip if the name ends in .gz)")->required();
  convert->add_option("--imu-data", req->imu_data,
                      "What the IMU file's six data columns hold: increments (rad, m/s: the i2Nav format) or "
                      "rates (rad/s, m/s², same axes and columns)")
      ->check(CLI::IsMember({"increments", "rates"}))
      ->capture_default_str();
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

int RunConvert(const ConvertRequest& req) {
  I2navInputs inputs;
  inputs.imu_path = req.imu_path;
  inputs.gnss_path = req.gnss_path;
  inputs.imu_data = req.imu_data == "rates" ? I2navImuData::kRates : I2navImuData::kIncrements;
  InputOptions options;
  options.on_error = req.on_error == "stop" ? InputErrorPolicy::kStop : InputErrorPolicy::kSkip;
  options.max_errors = req.max_errors;
  options.max_line_length = req.max_line_length;
  try {
    const I2navConversion result = ConvertI2nav(inputs, options, req.out_path);
    std::fputs(FormatConversionSummary(result).c_str(), stdout);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gins: error: %s\n", e.what());
    return 1;
  }
}

}  // namespace gins
