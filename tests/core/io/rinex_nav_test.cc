// RINEX 3 navigation files (core/io/rinex_nav.cc): the header's corrections, Keplerian and state-vector
// records with every field, BeiDou time, damage under both policies, and the bundled file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/io/rinex.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

std::string H(const std::string& content, const std::string& label) {
  std::string s = content;
  s.resize(60, ' ');
  return s + label + "\n";
}

std::string NavHeader(const std::string& extra = "", const std::string& version = "     3.04") {
  return H(version + "           N: GNSS NAV DATA    M: Mixed", "RINEX VERSION / TYPE") +
         H("GPSA    .1118D-07   .0000D+00  -.5960D-07   .0000D+00", "IONOSPHERIC CORR") +
         H("GAL     .1592D+03  -.4688D-01   .1895D-01", "IONOSPHERIC CORR") +
         H("GAUT   .9313225746D-09  .000000000D+00 345600 2381", "TIME SYSTEM CORR") + extra +
         H("", "END OF HEADER");
}
constexpr int kNavHeaderLines = 5;

// A D19.12 field as RINEX writers print it.
std::string D(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%19.12E", v);
  std::string s = buf;
  s[s.find('E')] = 'D';
  return s;
}

// A record: id and epoch, then `values` (3 on the first line, 4 on each next one).
std::string Record(const std::string& sat, const std::string& epoch, const std::vector<double>& values) {
  std::string s = sat + epoch;
  size_t i = 0;
  for (; i < 3 && i < values.size(); ++i) s += D(values[i]);
  while (i < values.size()) {
    s += "\n    ";
    for (int k = 0; k < 4 && i < values.size(); ++k, ++i) s += D(values[i]);
  }
  return s + "\n";
}

// GPS G05 at 2025-08-28 18:00:00: field n holds a value that names it (n + 1 where no range applies).
std::vector<double> KeplerFields(size_t count = 29) {
  std::vector<double> f(count);
  for (size_t n = 0; n < count; ++n) f[n] = static_cast<double>(n + 1);
  f[8] = 0.01;          // e
  f[10] = 5153.6;       // sqrt(A)
  f[11] = 410400.0;     // toe
  f[21] = 2381.0;       // week
  return f;
}

std::string WriteTemp(const std::string& text, const std::string& name = "walk.nav") {
  const std::string path = test::MakeTempDir("rinex_nav") + "/" + name;
  test::WriteFile(path, text);
  return path;
}

RinexNav Read(const std::string& path, InputErrorPolicy policy = InputErrorPolicy::kSkip) {
  InputOptions o;
  o.on_error = policy;
  return ReadRinexNav(path, o);
}

TEST(RinexNav, HeaderAndEveryKeplerField) {
  const RinexNav nav = Read(WriteTemp(NavHeader(H("    18", "LEAP SECONDS")) +
                                      Record("G05", " 2025 08 28 18 00 00", KeplerFields())));
  EXPECT_EQ(nav.header.version, 3.04);
  EXPECT_EQ(nav.header.leap_seconds, 18);
  ASSERT_EQ(nav.header.iono.size(), 2u);
  EXPECT_EQ(nav.header.iono[0].type, "GPSA");
  EXPECT_DOUBLE_EQ(nav.header.iono[0].params[2], -0.5960e-7);
  EXPECT_EQ(nav.header.iono[1].type, "GAL");
  EXPECT_DOUBLE_EQ(nav.header.iono[1].params[0], 159.2);
  ASSERT_EQ(nav.header.time_corrections.size(), 1u);
  EXPECT_EQ(nav.header.time_corrections[0].type, "GAUT");
  EXPECT_DOUBLE_EQ(nav.header.time_corrections[0].a0_s, 0.9313225746e-9);
  EXPECT_EQ(nav.header.time_corrections[0].ref_seconds_of_week, 345600);
  EXPECT_EQ(nav.header.time_corrections[0].ref_week, 2381);
  ASSERT_EQ(nav.kepler.size(), 1u) << FormatIssueCounts("skipped", nav.file.skipped, nav.file.issues);
  const KeplerEphemeris& k = nav.kepler[0];
  EXPECT_EQ(k.sat.ToString(), "G05");
  EXPECT_EQ(k.line, static_cast<uint64_t>(kNavHeaderLines + 2));
  EXPECT_EQ(k.toc_gps_s, 2381 * kSecondsPerWeek + 4 * 86400 + 18 * 3600);
  EXPECT_EQ(k.toe_gps_s(), 2381 * kSecondsPerWeek + 410400);
  const double got[] = {k.af0_s,     k.af1_s_s,     k.af2_s_s2,     k.iode,          k.crs_m,      k.delta_n_rad_s,
                        k.m0_rad,    k.cuc_rad,     k.e,            k.cus_rad,       k.sqrt_a_sqrt_m, k.toe_s,
                        k.cic_rad,   k.omega0_rad,  k.cis_rad,      k.i0_rad,        k.crc_m,      k.omega_rad,
                        k.omega_dot_rad_s, k.idot_rad_s, k.codes_on_l2, k.week,       k.l2p_data_flag, k.sv_accuracy_m,
                        k.health,    k.tgd_s,       k.iodc,         k.transmission_time_s, k.fit_interval_h};
  const std::vector<double> want = KeplerFields();
  for (size_t n = 0; n < want.size(); ++n) EXPECT_EQ(got[n], want[n]) << "field " << n;
  EXPECT_EQ(nav.records.at(GnssSystem::kGps), 1u);
}

TEST(RinexNav, SystemSpecificFieldsAndTimes) {
  const std::vector<double> f = KeplerFields();
  const RinexNav nav = Read(WriteTemp(NavHeader() + Record("E14", " 2025 08 28 17 10 00", KeplerFields(28)) +
                                      Record("C21", " 2025 08 28 17 00 00", f)));
  ASSERT_EQ(nav.kepler.size(), 2u) << FormatIssueCounts("skipped", nav.file.skipped, nav.file.issues);
  const KeplerEphemeris& e = nav.kepler[0];
  EXPECT_EQ(e.bgd_e5a_e1_s, f[25]);
  EXPECT_EQ(e.bgd_e5b_e1_s, f[26]);
  EXPECT_EQ(e.tgd_s, 0.0);
  EXPECT_EQ(e.codes_on_l2, f[20]);  // Galileo: data sources
  EXPECT_EQ(e.fit_interval_h, 0.0);
  const KeplerEphemeris& c = nav.kepler[1];
  EXPECT_EQ(c.tgd1_b1_b3_s, f[25]);
  EXPECT_EQ(c.tgd2_b2_b3_s, f[26]);
  EXPECT_EQ(c.aodc, f[28]);
  EXPECT_EQ(c.iodc, 0.0);
  // BDT = GPS − 14 s; the BDT week 2381 is GPS week 2381 + 1356.
  EXPECT_EQ(c.toc_gps_s, 2381 * kSecondsPerWeek + 4 * 86400 + 17 * 3600 + 14);
  EXPECT_EQ(c.toe_gps_s(), (2381 + kBdtWeekOffset) * kSecondsPerWeek + 410400 + 14);
}

TEST(RinexNav, StateVectorRecords) {
  std::vector<double> f(15);
  for (size_t n = 0; n < f.size(); ++n) f[n] = static_cast<double>(n) + 0.5;
  const std::string sbas = Record("S33", " 2025 08 28 17 28 32", f);
  // GLONASS is dated in UTC: it needs the header's LEAP SECONDS.
  const std::string glo = Record("R07", " 2025 08 28 17 15 00", f);
  const RinexNav nav = Read(WriteTemp(NavHeader(H("    18", "LEAP SECONDS")) + sbas + glo));
  ASSERT_EQ(nav.state.size(), 2u) << FormatIssueCounts("skipped", nav.file.skipped, nav.file.issues);
  const StateVectorEphemeris& s = nav.state[0];
  EXPECT_EQ(s.sat.ToString(), "S33");
  EXPECT_EQ(s.toc_gps_s, 2381 * kSecondsPerWeek + 4 * 86400 + 17 * 3600 + 28 * 60 + 32);
  EXPECT_EQ(s.clock_bias_s, 0.5);
  EXPECT_EQ(s.clock_drift_s_s, 1.5);
  EXPECT_EQ(s.message_frame_time_s, 2.5);
  EXPECT_EQ(s.position_km[0], 3.5);
  EXPECT_EQ(s.velocity_km_s[0], 4.5);
  EXPECT_EQ(s.acceleration_km_s2[0], 5.5);
  EXPECT_EQ(s.health, 6.5);
  EXPECT_EQ(s.position_km[1], 7.5);
  EXPECT_EQ(s.frequency_number_or_ura, 10.5);
  EXPECT_EQ(s.position_km[2], 11.5);
  EXPECT_EQ(s.acceleration_km_s2[2], 13.5);
  EXPECT_EQ(s.age_or_iodn, 14.5);
  EXPECT_EQ(nav.state[1].toc_gps_s, 2381 * kSecondsPerWeek + 4 * 86400 + 17 * 3600 + 15 * 60 + 18);
  EXPECT_EQ(nav.records.at(GnssSystem::kGlonass), 1u);
  EXPECT_EQ(nav.records.at(GnssSystem::kSbas), 1u);
  EXPECT_EQ(nav.file.total_skipped(), 0u);
  // Without LEAP SECONDS the file is refused at its first GLONASS record, whatever the policy.
  const std::string path = WriteTemp(NavHeader() + sbas + glo);
  for (const InputErrorPolicy policy : {InputErrorPolicy::kSkip, InputErrorPolicy::kStop}) {
    try {
      Read(path, policy);
      ADD_FAILURE() << "GLONASS without LEAP SECONDS read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + ":" + std::to_string(kNavHeaderLines + 5) + ": GLONASS record R07"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(RinexNav, GlonassHasFiveLinesFromVersion305) {
  std::vector<double> f(19);
  for (size_t n = 0; n < f.size(); ++n) f[n] = static_cast<double>(n) + 0.5;
  const RinexNav nav = Read(WriteTemp(NavHeader(H("    18", "LEAP SECONDS"), "     3.05") +
                                      Record("R07", " 2025 08 28 17 15 00", f) +
                                      Record("G05", " 2025 08 28 18 00 00", KeplerFields())));
  EXPECT_EQ(nav.file.total_skipped(), 0u) << FormatIssueCounts("skipped", nav.file.skipped, nav.file.issues);
  ASSERT_EQ(nav.state.size(), 1u);
  EXPECT_EQ(nav.state[0].age_or_iodn, 14.5);
  EXPECT_EQ(nav.kepler.size(), 1u);
}

TEST(RinexNav, RefusesHeadersItCannotRead) {
  auto refused = [](const std::string& text, const std::string& where_what) {
    const std::string path = WriteTemp(text);
    try {
      Read(path);
      ADD_FAILURE() << "not refused: " << where_what;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + ":" + where_what), std::string::npos) << e.what();
    }
  };
  refused(NavHeader("", "     2.11"), "1: RINEX version 2.11");
  std::string obs = NavHeader();
  obs.replace(obs.find("N: GNSS NAV DATA"), 16, "OBSERVATION DATA");
  refused(obs, "1: not a RINEX navigation file");
  std::string no_end = NavHeader();
  no_end.erase(no_end.find(H("", "END OF HEADER")));
  refused(no_end, "5: the header has no END OF HEADER");
  refused("", "1: empty file");
}

struct DamageCase {
  const char* name;
  std::string text;
  const char* reason;
  int line;
  size_t kept;
};

std::vector<DamageCase> DamageCases() {
  const std::string h = NavHeader();
  const std::string g = Record("G05", " 2025 08 28 18 00 00", KeplerFields());
  const std::string g2 = Record("G07", " 2025 08 28 18 00 00", KeplerFields());
  const int r1 = kNavHeaderLines + 1, r2 = kNavHeaderLines + 9;  // first lines of the records
  std::string bad_number = g;
  bad_number.replace(bad_number.find("D+01", 100) - 3, 1, "x");
  std::string blank_field = g;
  blank_field.replace(blank_field.find("\n    ") + 5, 19, std::string(19, ' '));
  std::vector<double> absurd = KeplerFields();
  absurd[8] = 1.5;  // e
  std::string bad_epoch = g;
  bad_epoch.replace(9, 2, "13");
  std::string cut = g.substr(0, g.rfind("\n    ") + 1);  // its last line missing
  std::string past80 = g;
  past80.insert(g.find('\n'), "  1.0");
  return {
      {"bad_number", h + bad_number + g2, "bad_number", r1, 1},
      {"blank_required_field", h + blank_field + g2, "missing_fields", r1, 1},
      {"absurd_orbit", h + Record("G05", " 2025 08 28 18 00 00", absurd) + g2, "absurd_value", r1, 1},
      {"bad_epoch", h + bad_epoch + g2, "bad_time", r1, 1},
      {"text_past_column_80", h + past80 + g2, "extra_fields", r1, 1},
      {"unknown_satellite", h + "X05" + g.substr(3) + g2, "unknown_type", r1, 1},
      {"record_cut_by_next", h + cut + g2, "missing_fields", r1, 1},
      {"truncated_at_end", h + g2 + cut, "truncated", r2, 1},
      {"truncated_mid_field", h + g2 + g.substr(0, g.size() - 10), "truncated", r2, 1},
      {"bad_leap_seconds", NavHeader(H("   x18", "LEAP SECONDS")) + g2, "bad_number", kNavHeaderLines, 1},
      {"bad_iono_parameter",
       NavHeader(H("BDSA    .1118D-07   .00x0D+00  -.5960D-07   .0000D+00", "IONOSPHERIC CORR")) + g2, "bad_number",
       kNavHeaderLines, 1},
      {"blank_iono_parameter", NavHeader(H("GPSB    .1118D-07", "IONOSPHERIC CORR")) + g2, "missing_fields",
       kNavHeaderLines, 1},
      {"bad_time_correction",
       NavHeader(H("GPUT   .9313225746D-09  .000000000D+00 3456x0 2381", "TIME SYSTEM CORR")) + g2, "bad_number",
       kNavHeaderLines, 1},
  };
}

TEST(RinexNav, DamageIsCountedOrStops) {
  for (const DamageCase& c : DamageCases()) {
    SCOPED_TRACE(c.name);
    const std::string path = WriteTemp(c.text, std::string(c.name) + ".nav");
    const RinexNav nav = Read(path);
    EXPECT_EQ(nav.file.total_skipped(), 1u) << FormatIssueCounts("skipped", nav.file.skipped, nav.file.issues);
    ASSERT_EQ(nav.file.skipped.count(c.reason), 1u) << FormatIssueCounts("skipped", nav.file.skipped, nav.file.issues);
    EXPECT_EQ(nav.file.issues.at(0).line, static_cast<uint64_t>(c.line)) << nav.file.issues.at(0).detail;
    EXPECT_EQ(nav.kepler.size(), c.kept);
    for (const KeplerEphemeris& k : nav.kepler) EXPECT_TRUE(std::isfinite(k.toc_gps_s) && std::isfinite(k.af0_s));
    try {
      Read(path, InputErrorPolicy::kStop);
      ADD_FAILURE() << "no InputError under stop";
    } catch (const InputError& e) {
      const std::string want = path + ":" + std::to_string(c.line) + ": " + c.reason;
      EXPECT_EQ(std::string(e.what()).rfind(want, 0), 0u) << e.what();
    }
  }
}

// The bundled file: every ephemeris of the u-blox walk (data/rinex/README.md).
TEST(RinexNav, WalkFile) {
  const RinexNav nav = Read(std::string(GINS_TEST_DATA_DIR) + "/rinex/walk.nav", InputErrorPolicy::kStop);
  EXPECT_EQ(nav.records.at(GnssSystem::kGps), 4u);
  EXPECT_EQ(nav.records.at(GnssSystem::kGalileo), 16u);
  EXPECT_EQ(nav.records.at(GnssSystem::kBeidou), 8u);
  EXPECT_EQ(nav.records.at(GnssSystem::kSbas), 5u);
  EXPECT_EQ(nav.kepler.size(), 28u);
  EXPECT_EQ(nav.state.size(), 5u);
  EXPECT_EQ(nav.header.leap_seconds, -1);
  ASSERT_EQ(nav.header.iono.size(), 1u);
  EXPECT_EQ(nav.header.iono[0].type, "GAL");
  EXPECT_DOUBLE_EQ(nav.header.iono[0].params[1], -0.4688e-1);
  ASSERT_EQ(nav.header.time_corrections.size(), 1u);
  EXPECT_EQ(nav.header.time_corrections[0].ref_week, 2381);

  const KeplerEphemeris* g10 = nullptr;
  const KeplerEphemeris* e14 = nullptr;
  const KeplerEphemeris* c21 = nullptr;
  for (const KeplerEphemeris& k : nav.kepler) {
    if (k.sat.ToString() == "G10") g10 = &k;
    if (k.sat.ToString() == "E14" && e14 == nullptr) e14 = &k;
    if (k.sat.ToString() == "C21") c21 = &k;
  }
  ASSERT_NE(g10, nullptr);
  EXPECT_EQ(g10->line, 85u);
  EXPECT_EQ(g10->toc_gps_s, 1440439200.0);  // 2025-08-28 18:00:00 GPST
  EXPECT_DOUBLE_EQ(g10->af0_s, -0.516209285706e-3);
  EXPECT_EQ(g10->iode, 97.0);
  EXPECT_DOUBLE_EQ(g10->crs_m, -13.96875);
  EXPECT_DOUBLE_EQ(g10->e, 0.104180137860e-1);
  EXPECT_DOUBLE_EQ(g10->sqrt_a_sqrt_m, 5153.64910889);
  EXPECT_EQ(g10->toe_s, 410400.0);
  EXPECT_EQ(g10->week, 2381.0);
  EXPECT_DOUBLE_EQ(g10->idot_rad_s, 0.493591988659e-9);
  EXPECT_EQ(g10->codes_on_l2, 1.0);
  EXPECT_EQ(g10->sv_accuracy_m, 2.0);
  EXPECT_DOUBLE_EQ(g10->tgd_s, 0.232830643654e-8);
  EXPECT_EQ(g10->iodc, 97.0);
  EXPECT_EQ(g10->transmission_time_s, 408666.0);
  EXPECT_EQ(g10->fit_interval_h, 4.0);
  ASSERT_NE(e14, nullptr);
  EXPECT_EQ(e14->toc_gps_s, 1440436200.0);  // 17:10:00 GST = GPST
  EXPECT_EQ(e14->codes_on_l2, 258.0);        // data sources: I/NAV E1-B + E5b, ...
  EXPECT_EQ(e14->sv_accuracy_m, 3.12);
  EXPECT_EQ(e14->health, 16.0);
  EXPECT_DOUBLE_EQ(e14->bgd_e5a_e1_s, -0.186264514923e-8);
  EXPECT_EQ(e14->bgd_e5b_e1_s, 0.0);
  ASSERT_NE(c21, nullptr);
  EXPECT_EQ(c21->toc_gps_s, 1440435614.0);  // 17:00:00 BDT = 17:00:14 GPST
  EXPECT_EQ(c21->week, 1025.0);             // BDT week
  EXPECT_EQ(c21->toe_gps_s(), 1440435614.0);
  EXPECT_DOUBLE_EQ(c21->tgd1_b1_b3_s, 0.133e-7);
  EXPECT_EQ(c21->aodc, 1.0);
  EXPECT_EQ(nav.state[0].sat.ToString(), "S33");
  EXPECT_DOUBLE_EQ(nav.state[0].position_km[0], -26638.871040);
  EXPECT_EQ(nav.state[0].toc_gps_s, 1440437312.0);
}

}  // namespace
}  // namespace gins
