// RINEX 3 navigation files (core/io/rinex.h): the header's corrections, then record by record.
#include <algorithm>

#include "core/io/rinex.h"

namespace gins {

using rinex_internal::Column;
using rinex_internal::IsBlank;
using rinex_internal::Label;
using rinex_internal::ParseCalendarFields;
using rinex_internal::ParseInt;
using rinex_internal::Trim;

namespace {

using input_reason::kAbsurdValue;
using input_reason::kBadNumber;
using input_reason::kMissingFields;
using input_reason::kNonFinite;
using input_reason::kTruncated;
using input_reason::kUnknownType;

constexpr int kMaxRecordLines = 8;
constexpr int kMaxFields = 4 * kMaxRecordLines;  // the epoch line's three, then four per line

// The file's last line without its newline, ending inside a field (fields end at column 4 + 19 k): the
// file was cut there, and the field's digits so far would read as a wrong number.
bool CutShort(const TextLine& line) {
  return !line.terminated && (line.text.size() < 4 || (line.text.size() - 4) % 19 != 0);
}

class NavParser {
 public:
  NavParser(RinexNav* nav, const InputOptions& options) : nav_(nav), lines_(&nav->file, options) {}

  void Read() {
    ReadHeader();
    TextLine line;
    while (Get(&line)) {
      if (IsBlank(line.text)) continue;
      ReadRecord(line);
    }
  }

 private:
  bool Get(TextLine* line) { return held_.Take(line) || lines_.Next(line); }
  void PutBack(const TextLine& line) { held_.Put(line); }

  void ReadHeader();
  void HeaderLine(const TextLine& line, std::string_view label);
  void ReadRecord(const TextLine& first);
  const char* Record(const std::string* texts, int count, std::string* detail);
  const char* Fields(const std::string* texts, int count, std::array<double, kMaxFields>* f,
                     std::array<bool, kMaxFields>* blank, std::string* detail) const;

  RinexNav* nav_;
  InputLines lines_;
  rinex_internal::HeldLine held_;
};

void NavParser::ReadHeader() {
  RinexNavHeader& h = nav_->header;
  TextLine line;
  bool first = true;
  while (Get(&line)) {
    const std::string_view label = Label(line.text);
    if (first) {
      first = false;
      bool blank = false;
      if (label != "RINEX VERSION / TYPE" ||
          ParseRinexNumber(Column(line.text, 1, 9), &h.version, &blank) != NumberStatus::kOk || blank) {
        lines_.issues().Refuse(line.number, "not a RINEX file: the first line is not a RINEX VERSION / TYPE line");
      }
      if (!(h.version >= 3.0 && h.version < 4.0)) {
        lines_.issues().Refuse(line.number, FormatText("RINEX version %.2f: only versions 3.00 to 3.0x are read",
                                                       h.version));
      }
      if (Column(line.text, 21, 1) != "N") {
        lines_.issues().Refuse(line.number, "not a RINEX navigation file (file type " +
                                                QuoteToken(Column(line.text, 21, 1)) + ", expected N)");
      }
      const std::string_view sys = Column(line.text, 41, 1);
      h.file_system = sys.empty() || sys == " " ? 'G' : sys[0];
      continue;
    }
    if (label == "END OF HEADER") {
      h.lines = line.number;
      return;
    }
    HeaderLine(line, label);
  }
  lines_.issues().Refuse(nav_->file.lines + 1, first ? "empty file" : "the header has no END OF HEADER");
}

void NavParser::HeaderLine(const TextLine& line, std::string_view label) {
  const std::string_view t = line.text;
  bool blank = false;
  if (label == "IONOSPHERIC CORR") {
    RinexIonoCorrection c;
    c.type = std::string(Trim(Column(t, 1, 4)));
    const int count = c.type == "GAL" ? 3 : 4;
    for (int i = 0; i < count; ++i) {
      const NumberStatus s = ParseRinexNumber(Column(t, 6 + 12 * i, 12), &c.params[i], &blank);
      if (s != NumberStatus::kOk || blank || c.type.empty()) {
        lines_.Damage(line, s == NumberStatus::kNonFinite ? kNonFinite : blank ? kMissingFields : kBadNumber,
                      FormatText("IONOSPHERIC CORR parameter %d %s", i, QuoteToken(Column(t, 6 + 12 * i, 12)).c_str()));
        return;
      }
    }
    nav_->header.iono.push_back(c);
  } else if (label == "TIME SYSTEM CORR") {
    RinexTimeCorrection c;
    c.type = std::string(Trim(Column(t, 1, 4)));
    bool blank2 = false;
    if (c.type.empty() || ParseRinexNumber(Column(t, 6, 17), &c.a0_s, &blank) != NumberStatus::kOk || blank ||
        ParseRinexNumber(Column(t, 23, 16), &c.a1_s_s, &blank2) != NumberStatus::kOk || blank2 ||
        !ParseInt(Column(t, 39, 7), &c.ref_seconds_of_week) || !ParseInt(Column(t, 46, 5), &c.ref_week)) {
      lines_.Damage(line, kBadNumber, "TIME SYSTEM CORR fields do not parse");
      return;
    }
    nav_->header.time_corrections.push_back(c);
  } else if (label == "LEAP SECONDS") {
    int leap = 0;
    if (!ParseInt(Column(t, 1, 6), &leap) || leap < 0 || leap > 100) {
      lines_.Damage(line, kBadNumber, "LEAP SECONDS " + QuoteToken(Column(t, 1, 6)) + " is not a count of seconds");
      return;
    }
    nav_->header.leap_seconds = leap;
  }
  // Other labels (PGM / RUN BY / DATE, COMMENT, ...) carry nothing the readers use.
}

// The lines of a record: its system decides how many; a line starting with a non-blank is the next record.
void NavParser::ReadRecord(const TextLine& first) {
  SatelliteId sat;
  if (!ParseSatelliteId(Column(first.text, 1, 3), &sat)) {
    lines_.Damage(first, kUnknownType, "not a navigation record: " + QuoteToken(Column(first.text, 1, 3)) +
                                           " is not a satellite id");
    // Its continuation lines (they start with blanks) go with it.
    TextLine line;
    while (Get(&line)) {
      if (!line.text.empty() && line.text[0] != ' ') {
        PutBack(line);
        return;
      }
    }
    return;
  }
  if (sat.system == GnssSystem::kGlonass && nav_->header.leap_seconds < 0) {
    // GLONASS epochs are UTC: without GPS − UTC no record of the file can be dated.
    lines_.issues().Refuse(first.number, "GLONASS record " + sat.ToString() +
                                             ": its epoch is UTC, and the header has no LEAP SECONDS");
  }
  if (CutShort(first)) {
    lines_.issues().Damage(first.number, kTruncated, sat.ToString() + " record's only line is cut mid-field");
    return;
  }
  int count = 8;
  if (sat.system == GnssSystem::kSbas) count = 4;
  if (sat.system == GnssSystem::kGlonass) count = nav_->header.version >= 3.05 ? 5 : 4;
  std::string texts[kMaxRecordLines];
  texts[0].assign(first.text);
  TextLine line;
  for (int i = 1; i < count; ++i) {
    const bool got = Get(&line);
    if (!got || (!line.text.empty() && line.text[0] != ' ')) {
      if (got) PutBack(line);
      lines_.issues().Damage(first.number, got ? kMissingFields : kTruncated,
                             FormatText("%s record has %d of its %d lines", sat.ToString().c_str(), i, count));
      return;
    }
    texts[i].assign(line.text);
    if (CutShort(line)) {
      lines_.issues().Damage(first.number, kTruncated, sat.ToString() + " record's last line is cut mid-field");
      return;
    }
  }
  std::string detail;
  if (const char* reason = Record(texts, count, &detail)) {
    lines_.issues().Damage(first.number, reason, sat.ToString() + " record: " + detail);
    return;
  }
  ++nav_->records[sat.system];
  if (sat.system == GnssSystem::kSbas || sat.system == GnssSystem::kGlonass) {
    nav_->state.back().line = first.number;
  } else {
    nav_->kepler.back().line = first.number;
  }
}

// Every field of the record's lines: the epoch line's three, then four per line. Spare fields may be blank.
const char* NavParser::Fields(const std::string* texts, int count, std::array<double, kMaxFields>* f,
                              std::array<bool, kMaxFields>* blank, std::string* detail) const {
  for (int i = 0; i < count; ++i) {
    const std::string_view t = texts[i];
    for (int k = i == 0 ? 1 : 0; k < 4; ++k) {
      const int n = i == 0 ? k - 1 : 3 + 4 * (i - 1) + k;
      const std::string_view field = Column(t, 5 + 19 * k, 19);
      const NumberStatus s = ParseRinexNumber(field, &(*f)[n], &(*blank)[n]);
      if (s != NumberStatus::kOk) {
        *detail = FormatText("line %d field %d %s is not a number", i + 1, k + 1, QuoteToken(field).c_str());
        return s == NumberStatus::kNonFinite ? kNonFinite : kBadNumber;
      }
    }
    if (!IsBlank(t.substr(std::min<size_t>(t.size(), 80)))) {
      *detail = FormatText("line %d has text past column 80", i + 1);
      return input_reason::kExtraFields;
    }
  }
  return nullptr;
}

const char* NavParser::Record(const std::string* texts, int count, std::string* detail) {
  SatelliteId sat;
  ParseSatelliteId(Column(texts[0], 1, 3), &sat);
  RinexCalendar toc;
  const std::string_view e = texts[0];
  if (!ParseCalendarFields(Column(e, 4, 5), Column(e, 9, 3), Column(e, 12, 3), Column(e, 15, 3), Column(e, 18, 3),
                           Column(e, 21, 3), &toc)) {
    *detail = "epoch " + QuoteToken(Column(e, 4, 20)) + " is not a date and time";
    return gnss_reason::kBadTime;
  }
  double toc_gps = 0.0;
  if (!RinexToGpsSeconds(toc, SystemTime(sat.system), nav_->header.leap_seconds, &toc_gps, detail)) {
    return gnss_reason::kBadTime;
  }
  std::array<double, kMaxFields> f{};
  std::array<bool, kMaxFields> blank{};
  if (const char* reason = Fields(texts, count, &f, &blank, detail)) return reason;
  // The clock and every field a position needs must be there; spare and flag fields may be blank.
  const bool state = sat.system == GnssSystem::kSbas || sat.system == GnssSystem::kGlonass;
  const int required = state ? 15 : 22;
  for (int n = 0; n < required; ++n) {
    const bool optional = state ? n == 6 || n == 10 || n == 14 : n == 20;  // health, codes, age/IODN
    if (blank[n] && !optional) {
      const int field = n < 3 ? n + 2 : (n - 3) % 4 + 1, record_line = n < 3 ? 1 : (n - 3) / 4 + 2;
      *detail = FormatText("field %d of line %d is blank", field, record_line);
      return kMissingFields;
    }
  }
  if (state) {
    StateVectorEphemeris s;
    s.sat = sat;
    s.toc = toc;
    s.toc_gps_s = toc_gps;
    s.clock_bias_s = f[0];
    s.clock_drift_s_s = f[1];
    s.message_frame_time_s = f[2];
    for (int a = 0; a < 3; ++a) {
      s.position_km[a] = f[3 + 4 * a];
      s.velocity_km_s[a] = f[4 + 4 * a];
      s.acceleration_km_s2[a] = f[5 + 4 * a];
    }
    s.health = f[6];
    s.frequency_number_or_ura = f[10];
    s.age_or_iodn = f[14];
    nav_->state.push_back(s);
    return nullptr;
  }
  KeplerEphemeris k;
  k.sat = sat;
  k.toc = toc;
  k.toc_gps_s = toc_gps;
  k.af0_s = f[0], k.af1_s_s = f[1], k.af2_s_s2 = f[2];
  k.iode = f[3], k.crs_m = f[4], k.delta_n_rad_s = f[5], k.m0_rad = f[6];
  k.cuc_rad = f[7], k.e = f[8], k.cus_rad = f[9], k.sqrt_a_sqrt_m = f[10];
  k.toe_s = f[11], k.cic_rad = f[12], k.omega0_rad = f[13], k.cis_rad = f[14];
  k.i0_rad = f[15], k.crc_m = f[16], k.omega_rad = f[17], k.omega_dot_rad_s = f[18];
  k.idot_rad_s = f[19], k.codes_on_l2 = f[20], k.week = f[21], k.l2p_data_flag = f[22];
  k.sv_accuracy_m = f[23], k.health = f[24];
  if (sat.system == GnssSystem::kGalileo) {
    k.bgd_e5a_e1_s = f[25], k.bgd_e5b_e1_s = f[26];
  } else if (sat.system == GnssSystem::kBeidou) {
    k.tgd1_b1_b3_s = f[25], k.tgd2_b2_b3_s = f[26];
  } else {
    k.tgd_s = f[25], k.iodc = f[26];
  }
  k.transmission_time_s = f[27];
  if (sat.system == GnssSystem::kBeidou) {
    k.aodc = f[28];
  } else if (sat.system != GnssSystem::kGalileo) {
    k.fit_interval_h = f[28];
  }
  if (!(k.e >= 0.0 && k.e < 1.0) || !(k.sqrt_a_sqrt_m > 0.0) || k.week < 0.0 || k.toe_s < 0.0 ||
      k.toe_s >= kSecondsPerWeek) {
    *detail = FormatText("orbit e %g, sqrt(A) %g, week %g, toe %g is not one", k.e, k.sqrt_a_sqrt_m, k.week, k.toe_s);
    return kAbsurdValue;
  }
  nav_->kepler.push_back(k);
  return nullptr;
}

}  // namespace

RinexNav ReadRinexNav(const std::string& path, const InputOptions& options) {
  RinexNav nav;
  nav.file.path = path;
  NavParser parser(&nav, options);
  parser.Read();
  return nav;
}

}  // namespace gins
