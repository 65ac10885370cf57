// Readers of the GNSS formats receivers and GNSS software write, as gins GNSS and GVEL records
// (docs/formats.md §6): RTKLIB solution files (rtklib_pos.cc), NMEA 0183 (nmea_reader.cc), and CSV files
// of IMU, wheel or GNSS data through a column map (csv_columns.h). Each streams its file once, in bounded
// memory, and gives records in strictly increasing time on the log's clock.
//
// Damage follows the gins reader's policy (InputOptions::on_error, max_errors; FileIssues): a damaged line
// is skipped and counted by reason with its line, or stops the conversion naming file:line: reason. Every
// record handed on has passed the log reader's own checks (CheckLogRecord), so the log reads back as written.
//
// Quality policy, the same for every format: a solution is kept with its own σ when the file gives one
// (RTKLIB's sdn/sde/sdu, NMEA GST); NMEA without GST takes σ = HDOP × the per-quality σ of kQualityPolicy.
// --min-quality drops solutions worse than a class (counted, not damage); no-solution and dead-reckoning
// entries are dropped (counted: a receiver's own dead reckoning fed back into an INS is not a measurement).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "core/io/gnss_text.h"
#include "core/io/log_reader.h"

namespace gins {

// Solution classes, best first (the order --min-quality uses).
enum class FixQuality { kFix, kFloat, kPpp, kDgps, kSbas, kSingle };
inline constexpr int kNumFixQualities = 6;

// "fix", "float", "ppp", "dgps", "sbas", "single".
const char* FixQualityName(FixQuality q);
bool ParseFixQuality(const std::string& name, FixQuality* q);

// NMEA's σ model without GST: σ east = σ north = HDOP × horizontal_m, σ up = HDOP × vertical_m (GGA has no
// VDOP; a vertical DOP about twice the horizontal is typical of an open sky).
struct QualitySigma {
  double horizontal_m;
  double vertical_m;
};
// Indexed by FixQuality.
inline constexpr QualitySigma kQualityPolicy[kNumFixQualities] = {
    {0.01, 0.02},  // fix: RTK fixed, cm
    {0.25, 0.5},   // float: RTK float, dm
    {0.1, 0.2},    // ppp
    {0.5, 1.0},    // dgps: code differential
    {1.0, 2.0},    // sbas
    {2.0, 4.0},    // single: stand-alone code (broadcast orbits and ionosphere)
};

struct GnssFormatOptions {
  LogTimeScale time_scale = LogTimeScale::kGps;  // the log's clock (--time-scale)
  FixQuality min_quality = FixQuality::kSingle;  // worse solutions are dropped
  // NMEA: the UTC date of the first epoch (days since 1980-01-06) for files without RMC or ZDA; -1: none.
  int64_t start_date_days = -1;
  // NMEA GVEL from RMC/VTG speed and course: the horizontal 1-σ per axis (m/s); vertical: vu = 0 with σ
  // max(vertical_sigma, vertical_per_speed × horizontal speed) (no vertical speed in NMEA; a 10 % grade at 1 σ).
  double velocity_sigma_m_s = 0.1;
  double vertical_velocity_sigma_m_s = 0.5;
  double vertical_sigma_per_speed = 0.1;
};

// What became of a GNSS file beyond ConvertedFile's lines, records and damage.
struct GnssFileStats {
  RecordCounts records{};                       // records given
  std::map<std::string, uint64_t> dropped;      // "quality single (below --min-quality float)" -> count
  std::map<int, uint64_t> leap_seconds;         // GPS − UTC applied (s) -> records
  std::map<std::string, uint64_t> qualities;    // quality class name -> GNSS records given
  std::map<std::string, uint64_t> ignored;      // sentences or entries not used, by kind (NMEA: "sentence GSV")
  std::string description;                      // the columns or sentences found, for the log's header
  std::string time_system;                      // "GPST" or "UTC" (JST is read as UTC); "" when kept as is
};

// A file of another format as log records (LogRecord) in strictly increasing time: GNSS and GVEL (a GVEL
// after the GNSS record of its epoch), or IMU or ODOM (CSV). Throws InputError as the damage policy says,
// and for a file that is not the format at all.
class RecordSource {
 public:
  virtual ~RecordSource() = default;
  virtual bool Next(LogRecord* record) = 0;
  const ConvertedFile& file() const { return file_; }
  const GnssFileStats& stats() const { return stats_; }

 protected:
  explicit RecordSource(const std::string& path) { file_.path = path; }
  // Checks the record as the log reader would (ranges, finiteness), counts it (GNSS by `quality`, a class
  // name), and keeps the time range. False (damage at `line`) if it would not read back.
  bool Accept(LogRecord* record, uint64_t line, FileIssues* issues, const char* quality, int leap_seconds);
  ConvertedFile file_;
  GnssFileStats stats_;
};

// RTKLIB solution files (rnx2rtkp, rtkpost, rtknavi; RTKLIB manual App. B "Solution file"): GPST, UTC or
// JST times in the calendar or week/seconds form; latitude/longitude (deg or d m s) and ellipsoidal height,
// or x/y/z-ecef; Q; ns; the σ (sdn sde sdu, or sdx..sdzx rotated into ENU at the point); velocity columns
// (out-outvel) become GVEL. The "%" header names the columns; without it the first line decides.
std::unique_ptr<RecordSource> OpenRtklibPos(const std::string& path, const InputOptions& options,
                                            const GnssFormatOptions& format);

// NMEA 0183: GGA (position, quality, HDOP), RMC (date, speed, course), GST (σ), VTG (speed, course), HDT or
// THS (heading), ZDA (date); any talker; checksums required. An epoch is the sentences sharing a time of day.
std::unique_ptr<RecordSource> OpenNmea(const std::string& path, const InputOptions& options,
                                       const GnssFormatOptions& format);

}  // namespace gins
