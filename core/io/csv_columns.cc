#include "core/io/csv_columns.h"

#include <algorithm>
#include <charconv>
#include <deque>
#include <vector>

namespace gins {
namespace {

using gnss_reason::kTimeBackwards;
using input_reason::kBadNumber;
using input_reason::kDuplicate;
using input_reason::kMissingFields;
using input_reason::kNonFinite;

constexpr double kStandardGravity = 9.80665;  // m/s² per g

struct Unit {
  const char* name;
  double scale;  // to SI (angles of positions and headings: to degrees, as the log has them)
};
// The units of a kind of quantity; the first is the default.
constexpr Unit kTime[] = {{"s", 1.0}, {"ms", 1e-3}, {"us", 1e-6}, {"ns", 1e-9}};
constexpr Unit kRate[] = {{"rad/s", 1.0}, {"deg/s", kDegToRad}};
constexpr Unit kAcc[] = {{"m/s2", 1.0}, {"g", kStandardGravity}};
constexpr Unit kPulses[] = {{"pulses", 1.0}};
constexpr Unit kAngle[] = {{"deg", 1.0}, {"rad", kRadToDeg}};
constexpr Unit kMetre[] = {{"m", 1.0}};
constexpr Unit kSpeed[] = {{"m/s", 1.0}};

struct Key {
  const char* name;
  const Unit* units;
  int n_units;
  bool required;
};
#define GINS_UNITS(u) u, static_cast<int>(sizeof(u) / sizeof(u[0]))
constexpr Key kImuKeys[] = {{"t", GINS_UNITS(kTime), true},  {"gx", GINS_UNITS(kRate), true},
                            {"gy", GINS_UNITS(kRate), true}, {"gz", GINS_UNITS(kRate), true},
                            {"ax", GINS_UNITS(kAcc), true},  {"ay", GINS_UNITS(kAcc), true},
                            {"az", GINS_UNITS(kAcc), true}};
constexpr Key kWheelKeys[] = {
    {"t", GINS_UNITS(kTime), true}, {"left", GINS_UNITS(kPulses), true}, {"right", GINS_UNITS(kPulses), true}};
constexpr Key kGnssKeys[] = {
    {"t", GINS_UNITS(kTime), true},     {"lat", GINS_UNITS(kAngle), true},      {"lon", GINS_UNITS(kAngle), true},
    {"h", GINS_UNITS(kMetre), true},    {"se", GINS_UNITS(kMetre), false},      {"sn", GINS_UNITS(kMetre), false},
    {"su", GINS_UNITS(kMetre), false},  {"heading", GINS_UNITS(kAngle), false}, {"ve", GINS_UNITS(kSpeed), false},
    {"vn", GINS_UNITS(kSpeed), false},  {"vu", GINS_UNITS(kSpeed), false},      {"sve", GINS_UNITS(kSpeed), false},
    {"svn", GINS_UNITS(kSpeed), false}, {"svu", GINS_UNITS(kSpeed), false}};
#undef GINS_UNITS
// GNSS key indices.
enum { kT = 0, kLat, kLon, kH, kSe, kSn, kSu, kHeading, kVe, kVn, kVu, kSve, kSvn, kSvu };

const Key* Keys(CsvKind kind, int* count) {
  switch (kind) {
    case CsvKind::kImu:
      *count = 7;
      return kImuKeys;
    case CsvKind::kWheel:
      *count = 3;
      return kWheelKeys;
    case CsvKind::kGnss:
      break;
  }
  *count = 14;
  return kGnssKeys;
}

std::string_view Trim(std::string_view s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  s = s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
  if (s.size() >= 2 && (s.front() == '"' || s.front() == '\'') && s.back() == s.front()) s = s.substr(1, s.size() - 2);
  return s;
}

bool AllDigits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// A time in `unit`: an integer count of ms, us or ns exactly split into seconds and their fraction (a
// double holds 1.7e18 ns only to 256 ns), anything else as a number times the scale.
NumberStatus ParseTime(std::string_view token, double scale, double* t) {
  int64_t v = 0;
  if (scale < 1.0 && AllDigits(token) &&
      std::from_chars(token.data(), token.data() + token.size(), v).ec == std::errc()) {  // else too many digits
    int64_t per = 1;
    for (double s = scale; s < 0.99; s *= 1000.0) per *= 1000;
    *t = static_cast<double>(v / per) + static_cast<double>(v % per) / static_cast<double>(per);
    return NumberStatus::kOk;
  }
  const NumberStatus status = ParseNumber(token, t);
  *t *= scale;
  return status;
}

class CsvReader : public RecordSource {
 public:
  CsvReader(const std::string& path, const ColumnMap& map, const InputOptions& options)
      : RecordSource(path), map_(map), lines_(&file_, options) {
    keys_ = Keys(map.kind, &n_keys_);
    stats_.description = "CSV, columns " + map.option + " \"" + map.text + "\"";
  }
  bool Next(LogRecord* record) override;

 private:
  bool FirstLine(const TextLine& line);  // true if it is the header
  const char* Convert(const TextLine& line, std::string* detail);
  bool Has(int key) const { return map_.columns[key].used; }

  ColumnMap map_;
  InputLines lines_;
  const Key* keys_ = nullptr;
  int n_keys_ = 0;
  bool first_ = true;
  FieldSplit split_ = FieldSplit::kWhitespace;
  char separator_ = ' ';
  int max_index_ = -1;
  std::vector<std::string_view> fields_;
  std::deque<LogRecord> pending_;
  bool have_last_ = false;
  double last_t_ = 0.0;
};

bool CsvReader::Next(LogRecord* record) {
  while (pending_.empty()) {
    TextLine line;
    if (!lines_.Next(&line)) return false;
    const std::string_view text = Trim(line.text);
    if (text.empty() || text[0] == '#') continue;
    if (first_) {
      first_ = false;
      if (FirstLine(line)) continue;
    }
    SplitFields(line.text, split_, separator_, &fields_);
    std::string detail;
    if (const char* reason = Convert(line, &detail)) lines_.Damage(line, reason, detail);
  }
  *record = pending_.front();
  pending_.pop_front();
  return true;
}

// The separator, the header if there is one, and the columns of the names the map uses.
bool CsvReader::FirstLine(const TextLine& line) {
  const std::string_view text = line.text;
  for (const char c : {',', ';', '\t'}) {
    if (text.find(c) != std::string_view::npos) {
      split_ = FieldSplit::kExact;
      separator_ = c;
      break;
    }
  }
  SplitFields(text, split_, separator_, &fields_);
  bool header = false;
  double v = 0.0;
  for (const std::string_view f : fields_) {
    header = header || (!Trim(f).empty() && ParseNumber(Trim(f), &v) == NumberStatus::kBad);
  }
  std::string names;
  for (size_t i = 0; i < fields_.size(); ++i) names += (i > 0 ? ", " : "") + std::string(Trim(fields_[i]));
  for (int k = 0; k < n_keys_; ++k) {
    CsvColumn& c = map_.columns[k];
    if (!c.used || c.name.empty()) continue;
    if (!header) {
      lines_.issues().Refuse(line.number, map_.option + " names column '" + c.name + "' (" + keys_[k].name +
                                              ") but the file has no header line");
    }
    for (size_t i = 0; i < fields_.size() && c.index < 0; ++i) {
      if (Trim(fields_[i]) == c.name) c.index = static_cast<int>(i);
    }
    if (c.index < 0) {
      lines_.issues().Refuse(line.number, map_.option + " names column '" + c.name + "' (" + keys_[k].name +
                                              "), which is not in the header: " + names);
    }
  }
  for (int k = 0; k < n_keys_; ++k) max_index_ = std::max(max_index_, map_.columns[k].index);
  return header;
}

const char* CsvReader::Convert(const TextLine& line, std::string* detail) {
  if (static_cast<int>(fields_.size()) <= max_index_) {
    int key = 0;
    for (int k = 0; k < n_keys_; ++k) {
      if (map_.columns[k].index >= static_cast<int>(fields_.size())) key = k;
    }
    *detail = FormatText("the line has %zu columns; %s puts %s in column %d", fields_.size(), map_.option.c_str(),
                         keys_[key].name, map_.columns[key].index + 1);
    return kMissingFields;
  }
  double v[kMaxCsvKeys] = {};
  bool present[kMaxCsvKeys] = {};
  for (int k = 0; k < n_keys_; ++k) {
    const CsvColumn& c = map_.columns[k];
    if (!c.used) continue;
    const std::string_view token = Trim(fields_[c.index]);
    if (token.empty() && map_.kind == CsvKind::kGnss && k == kHeading) continue;  // no heading at this fix
    const NumberStatus status = k == 0 ? ParseTime(token, c.scale, &v[k]) : ParseNumber(token, &v[k]);
    if (status != NumberStatus::kOk) {
      *detail = FormatText("column %d (%s) %s is %s", c.index + 1, keys_[k].name, QuoteToken(token).c_str(),
                           token.empty()                  ? "empty"
                           : status == NumberStatus::kBad ? "not a number"
                                                          : "not finite");
      return token.empty() ? kMissingFields : status == NumberStatus::kBad ? kBadNumber : kNonFinite;
    }
    if (k != 0) v[k] *= c.scale;
    present[k] = true;
  }
  const double t = v[0];
  if (have_last_ && t <= last_t_) {
    *detail =
        FormatText("t = %.6f s is %s the previous line's %.6f s", t, t == last_t_ ? "the same as" : "before", last_t_);
    return t == last_t_ ? kDuplicate : kTimeBackwards;
  }
  have_last_ = true;
  last_t_ = t;
  LogRecord r;
  if (map_.kind == CsvKind::kImu) {
    r.data = ImuSample{t, Vec3(v[1], v[2], v[3]), Vec3(v[4], v[5], v[6])};
  } else if (map_.kind == CsvKind::kWheel) {
    r.data = WheelRecord{t, v[1], v[2]};
  } else {
    GnssRecord& g = r.data.emplace<GnssRecord>();
    g.t = t;
    g.lat_deg = v[kLat];
    g.lon_deg = v[kLon];
    g.alt_m = v[kH];
    g.heading_valid = present[kHeading];
    g.heading_deg = v[kHeading];
    g.has_sigma = Has(kSe);
    g.sigma_enu = Vec3(v[kSe], v[kSn], v[kSu]);
  }
  if (!Accept(&r, line.number, &lines_.issues(), "csv", 0)) return nullptr;
  pending_.push_back(r);
  if (map_.kind != CsvKind::kGnss || !Has(kVe)) return nullptr;
  LogRecord vel{GnssVelocityRecord{t, Vec3(v[kVe], v[kVn], v[kVu]), Has(kSve), Vec3(v[kSve], v[kSvn], v[kSvu])}};
  if (Accept(&vel, line.number, &lines_.issues(), "csv", 0)) pending_.push_back(vel);
  return nullptr;
}

}  // namespace

const char* const* CsvKeys(CsvKind kind, int* count) {
  static const char* names[3][kMaxCsvKeys];
  const Key* keys = Keys(kind, count);
  const char** out = names[static_cast<int>(kind)];
  for (int k = 0; k < *count; ++k) out[k] = keys[k].name;
  return out;
}

ColumnMap ParseColumnMap(const std::string& spec, CsvKind kind, const std::string& option) {
  ColumnMap map;
  map.kind = kind;
  map.option = option;
  map.text = spec;
  int n = 0;
  const Key* keys = Keys(kind, &n);
  std::string all;
  for (int k = 0; k < n; ++k) all += std::string(k > 0 ? " " : "") + keys[k].name;
  auto fail = [&](const std::string& why) { throw InputError(option + ": " + why + " (in \"" + spec + "\")"); };
  std::vector<std::string_view> entries;
  SplitFields(spec, FieldSplit::kExact, ',', &entries);
  for (const std::string_view raw : entries) {
    const std::string_view entry = Trim(raw);
    if (entry.empty()) continue;
    const size_t eq = entry.find('=');
    if (eq == std::string_view::npos) fail("'" + std::string(entry) + "' is not key=column[:unit]");
    const std::string key(Trim(entry.substr(0, eq)));
    std::string_view column = Trim(entry.substr(eq + 1)), unit;
    const size_t colon = column.rfind(':');
    if (colon != std::string_view::npos) {
      unit = Trim(column.substr(colon + 1));
      column = Trim(column.substr(0, colon));
    }
    int k = 0;
    while (k < n && key != keys[k].name) ++k;
    if (k == n) fail("unknown key '" + key + "'; the keys are " + all);
    CsvColumn& c = map.columns[k];
    if (c.used) fail("'" + key + "' given twice");
    c.used = true;
    const bool negated = !column.empty() && column[0] == '-';
    if (negated) column.remove_prefix(1);
    if (negated && k == 0) fail("the time cannot be negated");
    if (column.empty()) fail("'" + key + "' names no column");
    double number = 0.0;
    if (AllDigits(column) && ParseNumber(column, &number) == NumberStatus::kOk) {
      if (number < 1 || number > 100000) fail("'" + key + "=" + std::string(column) + "': columns count from 1");
      c.index = static_cast<int>(number) - 1;
    } else {
      c.name = std::string(column);
    }
    const Key& spec_key = keys[k];
    int u = unit.empty() ? 0 : -1;
    for (int i = 0; i < spec_key.n_units && u < 0; ++i) {
      if (unit == spec_key.units[i].name) u = i;
    }
    if (u < 0) {
      std::string units;
      for (int i = 0; i < spec_key.n_units; ++i) units += std::string(i > 0 ? " | " : "") + spec_key.units[i].name;
      fail("unit '" + std::string(unit) + "' of '" + key + "' is not " + units);
    }
    c.unit = spec_key.units[u].name;
    c.scale = spec_key.units[u].scale * (negated ? -1.0 : 1.0);
  }
  for (int k = 0; k < n; ++k) {
    if (keys[k].required && !map.columns[k].used) fail("'" + std::string(keys[k].name) + "' is required");
  }
  if (kind == CsvKind::kGnss) {
    for (const int first : {kSe, kVe, kSve}) {
      const int used = map.columns[first].used + map.columns[first + 1].used + map.columns[first + 2].used;
      if (used != 0 && used != 3)
        fail(std::string(keys[first].name) + ".." + keys[first + 2].name + ": all three or none");
    }
    if (map.columns[kSve].used && !map.columns[kVe].used) fail("sve svn svu without ve vn vu");
  }
  return map;
}

std::unique_ptr<RecordSource> OpenCsv(const std::string& path, const ColumnMap& map, const InputOptions& options) {
  return std::make_unique<CsvReader>(path, map, options);
}

}  // namespace gins
