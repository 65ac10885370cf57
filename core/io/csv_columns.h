// CSV files of IMU, wheel or GNSS data, read through a column map that says which column is which quantity,
// in which unit and with which sign (docs/formats.md §6.3).
//
// A map is "key=COLUMN[:unit],...": COLUMN a 1-based column number (as every gins message counts columns)
// or a name from the file's header line, with a leading '-' to negate it (an axis that points the other way:
// FRD -> FLU is gy=-3,gz=-4). Keys, their units (the first is the default) and what is required:
//   all   t: s | ms | us | ns (the log's clock: the times are taken as they are, scaled)
//   imu   gx gy gz: rad/s | deg/s;  ax ay az: m/s2 | g (9.80665 m/s²). All six required.
//   wheel left right: pulses over the interval ending at t (ODOM records, docs/formats.md §3.3). Both required.
//   gnss  lat lon: deg | rad;  h: m (ellipsoidal);  se sn su: m (1-σ, all three or none);  heading: deg | rad
//         (compass, an empty field: no heading);  ve vn vu: m/s (a GVEL, all three or none);  sve svn svu:
//         m/s (its σ). lat, lon, h required.
// Fields are split at ',' (or ';' or tab, whichever the first line has; else at spaces), one header line
// allowed (a first line that is not all numbers), '#' lines are comments, fields are trimmed and may be
// quoted (no separators inside quotes).
#pragma once

#include <array>
#include <memory>
#include <string>

#include "core/io/gnss_formats.h"

namespace gins {

enum class CsvKind { kImu, kWheel, kGnss };

struct CsvColumn {
  bool used = false;
  int index = -1;      // 0-based, once resolved (a name is resolved against the header)
  std::string name;    // the header name, when the map gave one
  double scale = 1.0;  // unit -> SI, times the sign
  std::string unit;
};

// The quantities, in a fixed order: t, then the kind's keys.
inline constexpr int kMaxCsvKeys = 14;
struct ColumnMap {
  CsvKind kind = CsvKind::kGnss;
  std::string option;  // "--gnss-columns", for messages
  std::array<CsvColumn, kMaxCsvKeys> columns{};
  std::string text;  // as given
};

// Parses a map for a kind of file; throws InputError("<option>: <why>") for an unknown key or unit, a key
// given twice, a required key missing or σ/velocity keys given in part.
ColumnMap ParseColumnMap(const std::string& spec, CsvKind kind, const std::string& option);
// The key names of a kind, in ColumnMap::columns order ("t", "gx", ...), and their count.
const char* const* CsvKeys(CsvKind kind, int* count);

// The CSV file as IMU, ODOM, or GNSS (and GVEL) records in strictly increasing time. A line that lacks a
// column the map names is damage (missing_fields) under the policy, as is an empty or bad field; a header
// name the map uses that the header does not have refuses the file.
std::unique_ptr<RecordSource> OpenCsv(const std::string& path, const ColumnMap& map, const InputOptions& options);

}  // namespace gins
