// The broadcast ephemeris a GNSS model needs, as plain values (the RINEX reader, core/io/rinex.h, fills them;
// the models, core/gnss_orbit.h, use them without reading files): satellite ids, the GPS/BDT week constants
// and the Keplerian record with every broadcast field.
#pragma once

#include <string>

namespace gins {

enum class GnssSystem : char {
  kGps = 'G',
  kGlonass = 'R',
  kGalileo = 'E',
  kBeidou = 'C',
  kQzss = 'J',
  kSbas = 'S',
  kIrnss = 'I',
};

struct SatelliteId {
  GnssSystem system = GnssSystem::kGps;
  int prn = 0;  // 1..99 (SBAS: PRN − 100)

  std::string ToString() const;  // "G05", "S33"
  bool operator==(const SatelliteId& o) const { return system == o.system && prn == o.prn; }
  bool operator!=(const SatelliteId& o) const { return !(*this == o); }
  bool operator<(const SatelliteId& o) const {
    return system != o.system ? system < o.system : prn < o.prn;
  }
};

constexpr double kSecondsPerWeek = 604800.0;
// BDT began at 2006-01-01 00:00:00 UTC, GPS week 1356, when GPS − UTC was 14 s.
constexpr int kBdtWeekOffset = 1356;
constexpr double kGpsMinusBdt = 14.0;  // s

// A calendar epoch as a RINEX file writes it.
struct RinexCalendar {
  int year = 0, month = 0, day = 0, hour = 0, minute = 0;
  double second = 0.0;  // [0, 61)
};

// A broadcast Keplerian ephemeris of GPS, Galileo, BeiDou, QZSS or NavIC, every field of its RINEX record
// under its RINEX name. Angles are in radians (RINEX writes semicircles nowhere in version 3), times of week
// in seconds of the system's own week. A field the system does not have is 0.
struct KeplerEphemeris {
  SatelliteId sat;
  uint64_t line = 0;   // first line of the record
  RinexCalendar toc;   // the epoch as written, on the system's time
  double toc_gps_s = 0.0;  // clock reference time, GPS seconds (BeiDou: BDT converted)
  double af0_s = 0.0, af1_s_s = 0.0, af2_s_s2 = 0.0;  // SV clock bias, drift, drift rate
  // Orbit line 1
  double iode = 0.0;  // GPS/QZSS IODE, Galileo IODnav, BeiDou AODE, NavIC IODEC
  double crs_m = 0.0, delta_n_rad_s = 0.0, m0_rad = 0.0;
  // 2
  double cuc_rad = 0.0, e = 0.0, cus_rad = 0.0, sqrt_a_sqrt_m = 0.0;
  // 3
  double toe_s = 0.0;  // seconds of the week of `week`
  double cic_rad = 0.0, omega0_rad = 0.0, cis_rad = 0.0;
  // 4
  double i0_rad = 0.0, crc_m = 0.0, omega_rad = 0.0, omega_dot_rad_s = 0.0;
  // 5
  double idot_rad_s = 0.0;
  double codes_on_l2 = 0.0;   // GPS/QZSS; Galileo: data sources (bit 0 I/NAV E1-B, 1 F/NAV, 2 I/NAV E5b)
  double week = 0.0;          // GPS/QZSS/NavIC and Galileo: GPS week (continuous); BeiDou: BDT week
  double l2p_data_flag = 0.0; // GPS; QZSS
  // 6
  double sv_accuracy_m = 0.0;  // GPS/QZSS URA, Galileo SISA, BeiDou URA
  double health = 0.0;         // SV health (BeiDou SatH1)
  double tgd_s = 0.0;          // GPS/QZSS/NavIC TGD
  double bgd_e5a_e1_s = 0.0, bgd_e5b_e1_s = 0.0;  // Galileo
  double tgd1_b1_b3_s = 0.0, tgd2_b2_b3_s = 0.0;  // BeiDou
  double iodc = 0.0;           // GPS/QZSS
  // 7
  double transmission_time_s = 0.0;  // seconds of week of the message's transmission
  double fit_interval_h = 0.0;       // GPS/QZSS (QZSS: a flag, 0 = 2 h)
  double aodc = 0.0;                 // BeiDou

  double toe_gps_s() const;  // the time of ephemeris as GPS seconds (BeiDou: from its BDT week and seconds)
};

}  // namespace gins
