// NMEA 0183 (core/io/gnss_formats.h; docs/formats.md §6.2): the sentences (nmea_parse.h) grouped into
// epochs by their time of day; each epoch dated and put on the log's clock once, then given as a GNSS
// record (GGA; σ from GST or HDOP; heading from HDT/THS) and a GVEL (RMC or VTG speed and course).
#include <cmath>
#include <deque>

#include "core/io/gnss_formats.h"
#include "core/io/nmea_parse.h"

namespace gins {
namespace {

using gnss_reason::kMissingDate;
using gnss_reason::kTimeBackwards;
using input_reason::kDuplicate;

// Sentences of one epoch may print its time with different decimals (173021.75 and 173021.749): within
// this they are the same epoch. Receivers write NMEA at 100 Hz at most, 10 ms apart.
constexpr double kSameEpoch = 0.0051;  // s
constexpr int64_t kDay = 86400;

// What one epoch gathered: the first of each kind of value wins.
struct Epoch {
  bool open = false;
  NmeaSentence time;  // the timed sentence that opened it (sod, frac, leap_second)
  uint64_t first_line = 0, last_line = 0;
  bool has_date = false;
  int64_t days = 0;
  bool has_gga = false;
  NmeaSentence gga;
  uint64_t gga_line = 0;
  bool has_sigma = false;
  Vec3 sigma_enu = Vec3::Zero();
  bool has_velocity = false;
  double speed = 0.0;
  Vec3 v_enu = Vec3::Zero();
  bool has_heading = false;
  double heading = 0.0;
};

class NmeaReader : public RecordSource {
 public:
  NmeaReader(const std::string& path, const InputOptions& options, const GnssFormatOptions& format)
      : RecordSource(path), format_(format), lines_(&file_, options) {
    stats_.description = "NMEA 0183 GGA RMC GST VTG HDT THS ZDA";
    stats_.time_system = "UTC";
  }
  bool Next(LogRecord* record) override;

 private:
  // nullptr when the sentence was taken or ignored, else the damage reason with *detail.
  const char* Take(const NmeaSentence& s, uint64_t line, std::string* detail);
  void Close();
  bool Resolve(int64_t* days) const;
  void Emit(const Epoch& e, double t, int leap);

  const GnssFormatOptions format_;
  InputLines lines_;
  NmeaParser parser_;
  Epoch epoch_;
  std::deque<LogRecord> pending_;
  bool at_end_ = false;
  bool have_last_ = false;
  double last_t_ = 0.0;
  // The newest accepted epoch (UTC seconds since 1980-01-06): undated epochs take its date, moved by a day
  // where the time of day rolled over midnight.
  bool have_ref_ = false;
  int64_t ref_whole_ = 0;
};

bool NmeaReader::Next(LogRecord* record) {
  while (pending_.empty()) {
    if (at_end_) return false;
    TextLine line;
    if (!lines_.Next(&line)) {
      at_end_ = true;
      Close();
      continue;
    }
    if (line.text.find_first_not_of(" \t") == std::string_view::npos) continue;
    NmeaSentence s;
    std::string detail;
    const char* reason = parser_.Parse(line.text, &s, &detail);
    if (reason == nullptr) reason = Take(s, line.number, &detail);
    if (reason != nullptr) lines_.Damage(line, reason, detail);
  }
  *record = pending_.front();
  pending_.pop_front();
  return true;
}

const char* NmeaReader::Take(const NmeaSentence& s, uint64_t line, std::string* detail) {
  if (!s.prefix.empty()) lines_.issues().Warn(line, "text_before_sentence", QuoteToken(s.prefix));
  if (!s.ignored.empty()) {
    ++stats_.ignored[s.ignored];
    return nullptr;
  }
  if (s.timed) {
    const double apart = static_cast<double>(s.sod - epoch_.time.sod) + (s.frac - epoch_.time.frac);
    if (epoch_.open && std::abs(apart) > kSameEpoch) Close();
    if (!epoch_.open) {
      epoch_ = Epoch();
      epoch_.open = true;
      epoch_.time = s;
      epoch_.first_line = line;
    }
  } else if (!epoch_.open) {  // VTG, HDT, THS belong to the epoch of the timed sentence before them
    ++stats_
          .ignored[std::string(s.type == NmeaSentence::Type::kVtg ? "VTG" : "HDT/THS") + " before any timed sentence"];
    return nullptr;
  }
  epoch_.last_line = line;
  Epoch& e = epoch_;
  if (s.type == NmeaSentence::Type::kGga) {
    if (e.has_gga) {
      *detail = FormatText("a second GGA in the epoch of line %llu", static_cast<unsigned long long>(e.gga_line));
      return kDuplicate;
    }
    e.has_gga = true;
    e.gga = s;
    e.gga_line = line;
  }
  if (s.has_date && !e.has_date) {
    e.has_date = true;
    e.days = s.days;
  }
  if (s.has_velocity && !e.has_velocity) {
    e.has_velocity = true;
    e.speed = s.speed;
    e.v_enu = s.v_enu;
  }
  if (s.has_sigma && !e.has_sigma) {
    e.has_sigma = true;
    e.sigma_enu = s.sigma_enu;
  }
  if (s.has_heading && !e.has_heading) {
    e.has_heading = true;
    e.heading = s.heading;
  }
  return nullptr;
}

// The epoch's date: its own RMC or ZDA, else the newest accepted epoch's, moved across midnight (the time
// of day within half a day of it), else --date.
bool NmeaReader::Resolve(int64_t* days) const {
  if (epoch_.has_date) {
    *days = epoch_.days;
    return true;
  }
  if (!have_ref_) {
    *days = format_.start_date_days;
    return format_.start_date_days >= 0;
  }
  const int64_t sod = epoch_.time.sod;
  int64_t whole = ref_whole_ / kDay * kDay + sod;
  if (whole < ref_whole_ - kDay / 2) whole += kDay;
  if (whole > ref_whole_ + kDay / 2) whole -= kDay;
  *days = (whole - sod) / kDay;
  return true;
}

void NmeaReader::Close() {
  if (!epoch_.open) return;
  epoch_.open = false;
  const Epoch& e = epoch_;
  FixQuality quality;
  const char* no_measurement = nullptr;
  const bool fix = e.has_gga && GgaQuality(e.gga.quality, &quality, &no_measurement);
  if (!fix && !e.has_velocity) {  // nothing to give: a receiver's "no fix" before its first date is no damage
    if (no_measurement != nullptr) ++stats_.dropped[no_measurement];
    return;
  }
  const std::string lines = FormatText("epoch of lines %llu-%llu", static_cast<unsigned long long>(e.first_line),
                                       static_cast<unsigned long long>(e.last_line));
  int64_t days = 0;
  if (!Resolve(&days)) {
    lines_.issues().Damage(e.first_line, kMissingDate,
                           lines + ": no date yet (no RMC or ZDA in or before it; --date gives the first)");
    return;
  }
  SplitTime st;
  st.whole = days * kDay + e.time.sod;
  st.frac = e.time.frac;
  st.leap_second = e.time.leap_second;
  int leap = 0;
  const double t = ToLogTime(st, TimeSystem::kUtc, format_.time_scale, &leap);
  if (have_last_ && t <= last_t_) {
    lines_.issues().Damage(e.first_line, kTimeBackwards,
                           lines + FormatText(": t = %.3f s is not after the previous epoch's %.3f s", t, last_t_));
    return;
  }
  have_last_ = true;
  last_t_ = t;
  have_ref_ = true;
  ref_whole_ = st.whole;
  Emit(e, t, leap);
}

void NmeaReader::Emit(const Epoch& e, double t, int leap) {
  FixQuality quality = FixQuality::kSingle;
  const char* no_measurement = nullptr;
  if (e.has_gga && !GgaQuality(e.gga.quality, &quality, &no_measurement)) {
    ++stats_.dropped[no_measurement];
  } else if (e.has_gga && quality > format_.min_quality) {
    ++stats_.dropped[std::string("GGA ") + FixQualityName(quality) + " (below --min-quality " +
                     FixQualityName(format_.min_quality) + ")"];
  } else if (e.has_gga) {
    LogRecord r;
    GnssRecord& g = r.data.emplace<GnssRecord>();
    g.t = t;
    g.lat_deg = e.gga.lat;
    g.lon_deg = e.gga.lon;
    g.alt_m = e.gga.height;
    g.heading_valid = e.has_heading;
    g.heading_deg = e.heading;
    const QualitySigma& k = kQualityPolicy[static_cast<int>(quality)];
    const double hdop = e.gga.hdop;
    g.has_sigma = e.has_sigma || hdop > 0.0;
    g.sigma_enu = e.has_sigma ? e.sigma_enu : Vec3(hdop * k.horizontal_m, hdop * k.horizontal_m, hdop * k.vertical_m);
    if (!g.has_sigma) lines_.issues().Warn(e.gga_line, "no_sigma", "no GST and no HDOP: the fix has no σ");
    if (!e.gga.has_separation) {
      lines_.issues().Warn(e.gga_line, "no_geoid_separation",
                           "GGA without a geoid separation: its altitude taken as the ellipsoidal height");
    }
    if (Accept(&r, e.gga_line, &lines_.issues(), FixQualityName(quality), leap)) pending_.push_back(r);
  }
  if (!e.has_velocity) return;
  LogRecord r;
  GnssVelocityRecord& velocity = r.data.emplace<GnssVelocityRecord>();
  velocity.t = t;
  velocity.v_enu = e.v_enu;
  velocity.has_sigma = true;
  // NMEA has no vertical speed: vu = 0 with a σ that allows a grade of vertical_sigma_per_speed.
  const double h = format_.velocity_sigma_m_s;
  velocity.sigma_enu =
      Vec3(h, h, std::max(format_.vertical_velocity_sigma_m_s, format_.vertical_sigma_per_speed * e.speed));
  if (Accept(&r, e.first_line, &lines_.issues(), "", leap)) pending_.push_back(r);
}

}  // namespace

std::unique_ptr<RecordSource> OpenNmea(const std::string& path, const InputOptions& options,
                                       const GnssFormatOptions& format) {
  return std::make_unique<NmeaReader>(path, options, format);
}

}  // namespace gins
