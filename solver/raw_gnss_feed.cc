// Raw GNSS observations from RINEX 3 files (solver/raw_gnss_feed.h).
#include "solver/raw_gnss_feed.h"

#include <array>
#include <string_view>

namespace gins {

namespace {

struct SignalChoice {
  const char* code;
  GnssSignal signal;
};

// The first lists of SelectSignals, then the second ones; Galileo's second depends on the clock used
// (F/NAV: E1/E5a, I/NAV: E1/E5b), whose group delays make the combination exact.
const std::vector<SignalChoice>& FirstCodes(GnssSystem system) {
  static const std::vector<SignalChoice> kGps = {{"C1C", GnssSignal::kGpsL1Ca}};
  static const std::vector<SignalChoice> kGal = {{"C1C", GnssSignal::kGalileoE1}, {"C1X", GnssSignal::kGalileoE1}};
  static const std::vector<SignalChoice> kBds = {{"C2I", GnssSignal::kBeidouB1I},
                                                 {"C6I", GnssSignal::kBeidouB3I},
                                                 {"C1P", GnssSignal::kBeidouB1C},
                                                 {"C1X", GnssSignal::kBeidouB1C}};
  static const std::vector<SignalChoice> kNone;
  switch (system) {
    case GnssSystem::kGps: return kGps;
    case GnssSystem::kGalileo: return kGal;
    case GnssSystem::kBeidou: return kBds;
    default: return kNone;
  }
}

const std::vector<SignalChoice>& SecondCodes(GnssSystem system, bool galileo_fnav) {
  static const std::vector<SignalChoice> kGps = {{"C2W", GnssSignal::kGpsL2},
                                                 {"C2L", GnssSignal::kGpsL2},
                                                 {"C5Q", GnssSignal::kGpsL5},
                                                 {"C5X", GnssSignal::kGpsL5}};
  static const std::vector<SignalChoice> kGalInav = {{"C7Q", GnssSignal::kGalileoE5b},
                                                     {"C7X", GnssSignal::kGalileoE5b}};
  static const std::vector<SignalChoice> kGalFnav = {{"C5Q", GnssSignal::kGalileoE5a},
                                                     {"C5X", GnssSignal::kGalileoE5a}};
  static const std::vector<SignalChoice> kBds = {{"C6I", GnssSignal::kBeidouB3I}, {"C7I", GnssSignal::kBeidouB2I}};
  static const std::vector<SignalChoice> kNone;
  switch (system) {
    case GnssSystem::kGps: return kGps;
    case GnssSystem::kGalileo: return galileo_fnav ? kGalFnav : kGalInav;
    case GnssSystem::kBeidou: return kBds;
    default: return kNone;
  }
}

// "C1C" → "D1C", "S1C": the same band and attribute.
std::string WithType(const char* code, char type) {
  std::string s(code);
  s[0] = type;
  return s;
}

}  // namespace

RawGnssNav MakeRawGnssNav(const RinexNav& nav, const GnssRawOptions& options) {
  RawGnssNav out;
  out.ephemerides = nav.kepler;
  SppOptions& spp = out.spp;
  spp.elevation_mask_rad = options.elevation_mask;
  spp.sigma.a_m = spp.sigma.b_m = options.code_sigma;
  bool has_alpha = false, has_beta = false;
  for (const RinexIonoCorrection& c : nav.header.iono) {
    if (c.type == "GPSA") spp.klobuchar_alpha = c.params, has_alpha = true;
    if (c.type == "GPSB") spp.klobuchar_beta = c.params, has_beta = true;
  }
  const bool klobuchar = has_alpha && has_beta;
  using Iono = GnssRawOptions::Ionosphere;
  switch (options.ionosphere) {
    case Iono::kAuto:
      spp.ionosphere = klobuchar ? IonosphereModel::kKlobuchar : IonosphereModel::kIonosphereFree;
      break;
    case Iono::kKlobuchar:
      // Without GPSA/GPSB the parameters stay zero: no delay, and its σ (a fraction of it) zero too; so none.
      spp.ionosphere = klobuchar ? IonosphereModel::kKlobuchar : IonosphereModel::kNone;
      break;
    case Iono::kIonosphereFree: spp.ionosphere = IonosphereModel::kIonosphereFree; break;
    case Iono::kNone: spp.ionosphere = IonosphereModel::kNone; break;
  }
  // The combination E1/E5a is exact with the F/NAV clock (its reference); use it when the file has it.
  if (spp.ionosphere == IonosphereModel::kIonosphereFree) {
    for (const KeplerEphemeris& e : nav.kepler) {
      if (e.sat.system == GnssSystem::kGalileo && !IsGalileoInav(e)) out.galileo_fnav = true;
    }
  }
  spp.selection.galileo_inav = !out.galileo_fnav;
  out.doppler_sigma = options.doppler_sigma;
  out.use_doppler = options.use_doppler;
  out.phase_sigma = options.phase_sigma;
  out.use_phase = options.use_phase;
  return out;
}

std::vector<RawGnssObservation> SelectSignals(const std::vector<RinexSatelliteObs>& satellites,
                                              const RawGnssNav& nav) {
  std::vector<RawGnssObservation> out;
  const bool two = nav.spp.ionosphere == IonosphereModel::kIonosphereFree;
  for (const RinexSatelliteObs& s : satellites) {
    RawGnssObservation o;
    o.code.sat = s.sat;
    const char* first = nullptr;
    for (const SignalChoice& c : FirstCodes(s.sat.system)) {
      const RinexObservation* p = s.Find(c.code);
      if (p == nullptr || !(p->value > 0.0)) continue;
      first = c.code;
      o.code.signal = c.signal;
      o.code.pseudorange_m = p->value;
      break;
    }
    if (first == nullptr) continue;
    if (const RinexObservation* q = s.Find(WithType(first, 'S'))) o.code.cn0_dbhz = q->value;
    if (nav.use_doppler) {
      if (const RinexObservation* d = s.Find(WithType(first, 'D'))) {
        o.has_doppler = true;
        o.doppler_hz = d->value;
      }
    }
    if (nav.use_phase) {
      if (const RinexObservation* l = s.Find(WithType(first, 'L'))) {
        o.has_phase = true;
        o.phase_cycles = l->value;
        o.phase_lli = l->lli;
      }
    }
    if (two) {
      for (const SignalChoice& c : SecondCodes(s.sat.system, nav.galileo_fnav)) {
        if (std::string_view(c.code) == first) continue;
        const RinexObservation* p = s.Find(c.code);
        if (p == nullptr || !(p->value > 0.0)) continue;
        o.code.has_second = true;
        o.code.signal2 = c.signal;
        o.code.pseudorange2_m = p->value;
        break;
      }
    }
    out.push_back(o);
  }
  return out;
}

RawGnssFeed::RawGnssFeed(const GnssRawOptions& options, const InputOptions& input)
    : reader_(options.obs_file, input) {
  RinexNav nav = ReadRinexNav(options.nav_file, input);
  nav_ = std::make_shared<const RawGnssNav>(MakeRawGnssNav(nav, options));
  nav.kepler.clear();
  nav.state.clear();
  nav_file_stats_ = std::move(nav);
}

RawGnssFeed::~RawGnssFeed() = default;

bool RawGnssFeed::Fill() {
  if (next_ || ended_) return next_.has_value();
  RinexObsEpoch e;
  if (!reader_.Next(&e)) {
    ended_ = true;
    return false;
  }
  next_ = std::move(e);
  return true;
}

std::optional<double> RawGnssFeed::PeekTime() {
  if (!Fill()) return std::nullopt;
  return next_->gps_s;
}

bool RawGnssFeed::NextBefore(double t, RawGnssMeasurement* m) {
  if (!Fill() || next_->gps_s > t) return false;
  m->rx_gps_s = next_->gps_s;
  m->t = next_->gps_s;  // the pipeline takes the receiver clock off once the epoch's fix knows it
  m->nav = nav_;
  m->satellites = SelectSignals(next_->satellites, *nav_);
  m->has_fix = false;
  ++epochs_;
  satellites_ += m->satellites.size();
  without_signal_ += next_->satellites.size() - m->satellites.size();
  next_.reset();
  return true;
}

nlohmann::json RawGnssFeed::Stats() const {
  nlohmann::json j;
  j["obs_file"] = reader_.file().path;
  j["nav_file"] = nav_file_stats_.file.path;
  j["epochs"] = epochs_;
  j["satellites"] = satellites_;
  j["satellites_without_signal"] = without_signal_;
  j["ephemerides"] = nav_->ephemerides.size();
  j["obs_lines_skipped"] = reader_.file().total_skipped();
  j["nav_lines_skipped"] = nav_file_stats_.file.total_skipped();
  const char* iono = "none";
  if (nav_->spp.ionosphere == IonosphereModel::kKlobuchar) iono = "klobuchar";
  if (nav_->spp.ionosphere == IonosphereModel::kIonosphereFree) iono = "iono_free";
  j["ionosphere"] = iono;
  j["galileo_clock"] = nav_->galileo_fnav ? "fnav" : "inav";
  return j;
}

}  // namespace gins
