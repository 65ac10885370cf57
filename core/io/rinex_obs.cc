// RINEX 3 observation files (core/io/rinex.h): the header, then epoch by epoch, one epoch in memory.
#include <algorithm>
#include <cstring>

#include "core/io/rinex.h"

namespace gins {

using rinex_internal::Column;
using rinex_internal::IsBlank;
using rinex_internal::Label;
using rinex_internal::ParseCalendarFields;
using rinex_internal::ParseInt;
using rinex_internal::Trim;

const RinexObservation* RinexSatelliteObs::Find(std::string_view code) const {
  for (const RinexObservation& o : obs) {
    if (o.code == code) return &o;
  }
  return nullptr;
}

namespace {

using gnss_reason::kBadTime;
using input_reason::kBadNumber;
using input_reason::kDuplicate;
using input_reason::kExtraFields;
using input_reason::kMissingFields;
using input_reason::kNonFinite;
using input_reason::kOutOfOrder;
using input_reason::kTruncated;
using input_reason::kUnknownType;

constexpr size_t kSatColumns = 3;  // the satellite id
constexpr size_t kObsColumns = 16;  // F14.3, LLI, SSI

}  // namespace

class RinexObsReader::Impl {
 public:
  Impl(RinexObsReader* r, const InputOptions& options) : r_(r), lines_(&r->file_, options) {}
  void ReadHeader();
  bool Next(RinexObsEpoch* epoch);

 private:
  bool Get(TextLine* line) { return held_.Take(line) || lines_.Next(line); }
  void PutBack(const TextLine& line) { held_.Put(line); }
  [[noreturn]] void Refuse(uint64_t line, const std::string& message) { lines_.issues().Refuse(line, message); }
  void HeaderLine(const TextLine& line, std::string_view label);
  void ObsTypes(const TextLine& line);
  void FinishObsTypes(uint64_t line);
  const char* EpochLine(std::string_view t, RinexCalendar* c, int* flag, int* count, RinexObsEpoch* e,
                        std::string* detail) const;
  const char* SatelliteLine(const TextLine& line, RinexSatelliteObs* s, std::string* detail) const;
  // Reads `count` lines of an event or cycle slip record; false if a '>' or the end came first.
  bool SkipLines(int count, int flag, uint64_t* skipped);

  RinexObsReader* r_;
  InputLines lines_;
  rinex_internal::HeldLine held_;
  // SYS / # / OBS TYPES being read: its system and the count it announced.
  bool types_open_ = false;
  GnssSystem types_system_ = GnssSystem::kGps;
  int types_count_ = 0;
  uint64_t first_obs_line_ = 0;
  RinexCalendar first_obs_;
  bool has_time_ = false;
  double last_gps_s_ = 0.0;
  bool resync_ = false;  // after a damaged epoch line: its satellite lines go with it
};

void RinexObsReader::Impl::FinishObsTypes(uint64_t line) {
  if (!types_open_) return;
  const size_t have = r_->header_.obs_types[types_system_].size();
  if (have != static_cast<size_t>(types_count_)) {
    Refuse(line, FormatText("SYS / # / OBS TYPES of %c announces %d types and lists %zu",
                            static_cast<char>(types_system_), types_count_, have));
  }
  types_open_ = false;
}

// "G   12 C1C L1C ..." and its continuation lines (blank in 1-6) of 13 types each.
void RinexObsReader::Impl::ObsTypes(const TextLine& line) {
  const std::string_view t = line.text;
  if (!IsBlank(Column(t, 1, 6))) {
    FinishObsTypes(line.number);
    int count = 0;
    if (t.empty() || !ParseGnssSystem(t[0], &types_system_) || !ParseInt(Column(t, 4, 3), &count) || count < 1) {
      Refuse(line.number, "SYS / # / OBS TYPES: " + QuoteToken(Column(t, 1, 6)) + " is not a system and a count");
    }
    types_open_ = true;
    types_count_ = count;
    r_->header_.obs_types[types_system_].clear();  // a later declaration (an event) replaces the earlier
  } else if (!types_open_) {
    Refuse(line.number, "SYS / # / OBS TYPES continuation line without its first line");
  }
  std::vector<std::string>& types = r_->header_.obs_types[types_system_];
  for (size_t k = 0; k < 13 && types.size() < static_cast<size_t>(types_count_); ++k) {
    const std::string_view code = Column(t, 8 + 4 * k, 3);
    if (IsBlank(code)) break;  // fewer codes than announced: FinishObsTypes says so
    if (code.size() != 3 || std::strchr("CLDSIX", code[0]) == nullptr || code[1] < '0' || code[1] > '9') {
      Refuse(line.number, "SYS / # / OBS TYPES: " + QuoteToken(code) + " is not an observation code");
    }
    types.emplace_back(code);
  }
  if (types.size() == static_cast<size_t>(types_count_)) types_open_ = false;
}

void RinexObsReader::Impl::HeaderLine(const TextLine& line, std::string_view label) {
  RinexObsHeader& h = r_->header_;
  const std::string_view t = line.text;
  if (label == "SYS / # / OBS TYPES") {
    ObsTypes(line);
    return;
  }
  FinishObsTypes(line.number);
  auto numbers = [&](int n, int width, double* out) {
    for (int i = 0; i < n; ++i) {
      bool blank = false;
      const std::string_view field = Column(t, 1 + width * i, width);
      const NumberStatus s = ParseRinexNumber(field, &out[i], &blank);
      if (s != NumberStatus::kOk || blank) {
        lines_.Damage(line, s == NumberStatus::kNonFinite ? kNonFinite : blank ? kMissingFields : kBadNumber,
                      std::string(label) + " field " + std::to_string(i + 1) + " " + QuoteToken(field));
        return false;
      }
    }
    return true;
  };
  double v[3];
  if (label == "APPROX POSITION XYZ") {
    if (numbers(3, 14, v)) {
      h.has_approx_position = true;
      h.approx_position_ecef_m = {v[0], v[1], v[2]};
    }
  } else if (label == "ANTENNA: DELTA H/E/N") {
    if (numbers(3, 14, v)) h.antenna_delta_hen_m = {v[0], v[1], v[2]};
  } else if (label == "INTERVAL") {
    if (numbers(1, 10, v)) h.interval_s = v[0];
  } else if (label == "LEAP SECONDS") {
    int leap = 0;
    if (!ParseInt(Column(t, 1, 6), &leap) || leap < 0 || leap > 100) {
      lines_.Damage(line, kBadNumber, "LEAP SECONDS " + QuoteToken(Column(t, 1, 6)) + " is not a count of seconds");
    } else {
      h.leap_seconds = leap;
    }
  } else if (label == "TIME OF FIRST OBS") {
    // It fixes the time system of every epoch: without it nothing can be dated.
    RinexCalendar c;
    if (!ParseCalendarFields(Column(t, 1, 6), Column(t, 7, 6), Column(t, 13, 6), Column(t, 19, 6),
                             Column(t, 25, 6), Column(t, 31, 13), &c)) {
      Refuse(line.number, "TIME OF FIRST OBS " + QuoteToken(Column(t, 1, 43)) + " is not a date and time");
    }
    const std::string_view sys = Trim(Column(t, 49, 3));
    GnssSystem file_system;
    if (sys.empty() && h.file_system != 'M' && ParseGnssSystem(h.file_system, &file_system)) {
      h.time_system = SystemTime(file_system);  // a single-system file may leave it blank
    } else if (!ParseRinexTimeSystem(sys, &h.time_system)) {
      Refuse(line.number, "TIME OF FIRST OBS: time system " + QuoteToken(sys) +
                              " is not one of GPS GAL BDT QZS IRN GLO UTC (a mixed file must name it)");
    }
    first_obs_line_ = line.number;
    first_obs_ = c;
  }
  // Other labels (MARKER NAME, REC # / TYPE / VERS, SYS / PHASE SHIFT, ...) carry nothing the reader uses.
}

void RinexObsReader::Impl::ReadHeader() {
  RinexObsHeader& h = r_->header_;
  TextLine line;
  bool first = true;
  while (Get(&line)) {
    const std::string_view label = Label(line.text);
    if (first) {
      first = false;
      bool blank = false;
      if (label != "RINEX VERSION / TYPE" ||
          ParseRinexNumber(Column(line.text, 1, 9), &h.version, &blank) != NumberStatus::kOk || blank) {
        Refuse(line.number, "not a RINEX file: the first line is not a RINEX VERSION / TYPE line");
      }
      if (!(h.version >= 3.0 && h.version < 4.0)) {
        Refuse(line.number, FormatText("RINEX version %.2f: only versions 3.00 to 3.0x are read", h.version));
      }
      if (Column(line.text, 21, 1) != "O") {
        Refuse(line.number, "not a RINEX observation file (file type " + QuoteToken(Column(line.text, 21, 1)) +
                                ", expected O)");
      }
      const std::string_view sys = Column(line.text, 41, 1);
      h.file_system = sys.empty() || sys == " " ? 'G' : sys[0];
      continue;
    }
    if (label == "END OF HEADER") {
      FinishObsTypes(line.number);
      h.lines = line.number;
      if (h.obs_types.empty()) Refuse(line.number, "the header has no SYS / # / OBS TYPES");
      if (first_obs_line_ == 0) Refuse(line.number, "the header has no TIME OF FIRST OBS (it names the time system)");
      std::string why;
      if (!RinexToGpsSeconds(first_obs_, h.time_system, h.leap_seconds, &h.first_obs_gps_s, &why)) {
        Refuse(first_obs_line_, "TIME OF FIRST OBS: " + why);
      }
      return;
    }
    HeaderLine(line, label);
  }
  Refuse(r_->file_.lines + 1, first ? "empty file" : "the header has no END OF HEADER");
}

// "> 2025 08 28 17 30 39.7480000  0 28      -0.123456789012": the calendar, the flag, the count, the clock.
const char* RinexObsReader::Impl::EpochLine(std::string_view t, RinexCalendar* c, int* flag, int* count,
                                            RinexObsEpoch* e, std::string* detail) const {
  if (!ParseInt(Column(t, 32, 1), flag) || *flag > 6 || !ParseInt(Column(t, 33, 3), count) || *count < 0) {
    *detail = "epoch flag and count " + QuoteToken(Column(t, 32, 4)) + " are not a flag 0-6 and a number";
    return kBadNumber;
  }
  if (*flag >= 2 && *flag <= 5) return nullptr;  // an event: the date may be blank, and is not used
  if (!ParseCalendarFields(Column(t, 3, 4), Column(t, 8, 2), Column(t, 11, 2), Column(t, 14, 2), Column(t, 17, 2),
                           Column(t, 19, 11), c)) {
    *detail = "epoch " + QuoteToken(Column(t, 1, 29)) + " is not a date and time";
    return kBadTime;
  }
  if (!RinexToGpsSeconds(*c, r_->header_.time_system, r_->header_.leap_seconds, &e->gps_s, detail)) return kBadTime;
  bool blank = false;
  const NumberStatus s = ParseRinexNumber(Column(t, 42, 15), &e->receiver_clock_offset_s, &blank);
  if (s != NumberStatus::kOk) {
    *detail = "receiver clock offset " + QuoteToken(Column(t, 42, 15)) + " is not a number";
    return s == NumberStatus::kNonFinite ? kNonFinite : kBadNumber;
  }
  e->has_clock_offset = !blank;
  if (!IsBlank(t.substr(std::min<size_t>(t.size(), 56)))) {
    *detail = "text past the receiver clock offset (column 56)";
    return kExtraFields;
  }
  return nullptr;
}

const char* RinexObsReader::Impl::SatelliteLine(const TextLine& line, RinexSatelliteObs* s,
                                                std::string* detail) const {
  const std::string_view t = line.text;
  if (!ParseSatelliteId(Column(t, 1, 3), &s->sat)) {
    *detail = QuoteToken(Column(t, 1, 3)) + " is not a satellite id";
    return kUnknownType;
  }
  const auto it = r_->header_.obs_types.find(s->sat.system);
  if (it == r_->header_.obs_types.end()) {
    *detail = s->sat.ToString() + ": the header has no SYS / # / OBS TYPES for its system";
    return kUnknownType;
  }
  const std::vector<std::string>& types = it->second;
  const size_t width = kSatColumns + kObsColumns * types.size();
  if (!IsBlank(t.substr(std::min(t.size(), width)))) {
    *detail = FormatText("%s: text past its %zu observations (column %zu)", s->sat.ToString().c_str(), types.size(),
                         width);
    return kExtraFields;
  }
  // Lines may stop after their last observation, but a cut last line of the file is not that.
  if (!line.terminated && t.size() < width && (t.size() < kSatColumns || (t.size() - kSatColumns) % kObsColumns != 0)) {
    *detail = s->sat.ToString() + ": the file's last line ends inside a field";
    return kTruncated;
  }
  s->obs.clear();
  for (size_t k = 0; k < types.size(); ++k) {
    const size_t at = 1 + kSatColumns + kObsColumns * k;
    RinexObservation o;
    bool blank = false;
    const NumberStatus st = ParseRinexNumber(Column(t, at, 14), &o.value, &blank);
    if (st != NumberStatus::kOk) {
      *detail = s->sat.ToString() + " " + types[k] + " " + QuoteToken(Column(t, at, 14)) + " is not a number";
      return st == NumberStatus::kNonFinite ? kNonFinite : kBadNumber;
    }
    const std::string_view lli = Column(t, at + 14, 1), ssi = Column(t, at + 15, 1);
    if ((!IsBlank(lli) && !ParseInt(lli, &o.lli)) || (!IsBlank(ssi) && !ParseInt(ssi, &o.ssi)) || o.lli > 7) {
      *detail = s->sat.ToString() + " " + types[k] + " LLI/SSI " + QuoteToken(Column(t, at + 14, 2)) +
                " is not two digits";
      return kBadNumber;
    }
    if (blank) continue;  // missing (an LLI alone says nothing without its value)
    o.code = types[k];
    s->obs.push_back(std::move(o));
  }
  return nullptr;
}

bool RinexObsReader::Impl::SkipLines(int count, int flag, uint64_t* skipped) {
  TextLine line;
  for (int i = 0; i < count; ++i) {
    if (!Get(&line)) return false;
    if (!line.text.empty() && line.text[0] == '>') {
      PutBack(line);
      return false;
    }
    ++*skipped;
    // New site or header information: the header lines of the event apply from here on.
    if (flag == 3 || flag == 4) {
      const std::string_view label = Label(line.text);
      if (label == "SYS / # / OBS TYPES" || label == "INTERVAL" || label == "ANTENNA: DELTA H/E/N" ||
          label == "APPROX POSITION XYZ") {
        HeaderLine(line, label);
      }
    }
  }
  FinishObsTypes(line.number);
  return true;
}

bool RinexObsReader::Impl::Next(RinexObsEpoch* epoch) {
  RinexObsStats& stats = r_->stats_;
  TextLine line;
  while (Get(&line)) {
    if (line.text.empty() || line.text[0] != '>') {
      if (resync_ || IsBlank(line.text)) continue;  // a damaged epoch's lines, counted with it
      lines_.Damage(line, kUnknownType, "expected an epoch line ('>'), got " + QuoteToken(line.text.substr(0, 20)));
      continue;
    }
    resync_ = false;
    RinexCalendar c;
    int flag = 0, count = 0;
    std::string detail;
    epoch->has_clock_offset = false;
    epoch->receiver_clock_offset_s = 0.0;
    if (const char* reason = EpochLine(line.text, &c, &flag, &count, epoch, &detail)) {
      lines_.Damage(line, reason, detail);
      resync_ = true;
      continue;
    }
    const uint64_t at = line.number;
    if (flag >= 2) {
      const bool complete = SkipLines(count, flag, flag == 6 ? &stats.cycle_slip_lines : &stats.event_lines);
      ++(flag == 6 ? stats.cycle_slip_epochs : stats.event_epochs);
      if (!complete) {
        lines_.issues().Damage(at, held_.holds() ? kMissingFields : kTruncated,
                               FormatText("epoch flag %d announces %d records; fewer follow", flag, count));
      }
      continue;
    }
    epoch->flag = flag;
    epoch->line = at;
    epoch->satellites.resize(static_cast<size_t>(count));
    size_t kept = 0;
    int read = 0;
    for (; read < count; ++read) {
      if (!Get(&line)) break;
      if (!line.terminated && read + 1 < count) break;  // the file ends inside the epoch: damage of the epoch
      if (!line.text.empty() && line.text[0] == '>') {
        PutBack(line);
        break;
      }
      RinexSatelliteObs& s = epoch->satellites[kept];
      if (const char* reason = SatelliteLine(line, &s, &detail)) {
        lines_.Damage(line, reason, detail);
        continue;
      }
      bool duplicate = false;
      for (size_t k = 0; k < kept; ++k) duplicate = duplicate || epoch->satellites[k].sat == s.sat;
      if (duplicate) {
        lines_.Damage(line, kDuplicate, s.sat.ToString() + " appears twice in the epoch of line " + std::to_string(at));
        continue;
      }
      ++kept;
    }
    epoch->satellites.resize(kept);
    if (read < count) {
      // Cut at the end of the file or by the next epoch: the epoch is not whole, and it is not given.
      lines_.issues().Damage(at, held_.holds() ? kMissingFields : kTruncated,
                             FormatText("epoch announces %d satellites, %d lines follow", count, read));
      continue;
    }
    if (has_time_ && epoch->gps_s <= last_gps_s_) {
      lines_.issues().Damage(at, epoch->gps_s == last_gps_s_ ? kDuplicate : kOutOfOrder,
                             FormatText("epoch %.7f s is not after the previous one (%.7f s)", epoch->gps_s,
                                        last_gps_s_));
      continue;
    }
    has_time_ = true;
    last_gps_s_ = epoch->gps_s;
    ++stats.epochs;
    stats.satellite_records += kept;
    return true;
  }
  return false;
}

RinexObsReader::RinexObsReader(const std::string& path, const InputOptions& options) {
  file_.path = path;
  impl_ = std::make_unique<Impl>(this, options);
  impl_->ReadHeader();
}

RinexObsReader::~RinexObsReader() = default;

bool RinexObsReader::Next(RinexObsEpoch* epoch) { return impl_->Next(epoch); }

}  // namespace gins
