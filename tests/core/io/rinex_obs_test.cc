// RINEX 3 observation files (core/io/rinex_obs.cc) and the shared pieces (satellite ids, RINEX times as GPS
// seconds): the header, epochs, events, every kind of damage under both policies, and the bundled excerpt.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "core/io/rinex.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kWalkGps = 1440437439.748;  // 2025-08-28 17:30:39.748 GPST

TEST(RinexTime, CalendarToGpsSeconds) {
  std::string why;
  double t = 0.0;
  ASSERT_TRUE(RinexToGpsSeconds({2025, 8, 28, 17, 30, 39.748}, RinexTimeSystem::kGps, -1, &t, &why)) << why;
  EXPECT_DOUBLE_EQ(t, kWalkGps);
  const GpsWeekTime w = ToGpsWeek(t);
  EXPECT_EQ(w.week, 2381);
  EXPECT_NEAR(w.seconds_of_week, 4 * 86400 + 17 * 3600 + 30 * 60 + 39.748, 1e-6);  // a Thursday
  ASSERT_TRUE(RinexToGpsSeconds({1980, 1, 6, 0, 0, 0.0}, RinexTimeSystem::kGps, -1, &t, &why));
  EXPECT_EQ(t, 0.0);
  ASSERT_TRUE(RinexToGpsSeconds({2006, 1, 1, 0, 0, 0.0}, RinexTimeSystem::kBeidou, -1, &t, &why));
  EXPECT_EQ(ToGpsWeek(t).week, kBdtWeekOffset);  // BDT's epoch: GPS week 1356, 14 s into it
  EXPECT_EQ(ToGpsWeek(t).seconds_of_week, 14.0);
  ASSERT_TRUE(RinexToGpsSeconds({2025, 8, 28, 17, 30, 39.748}, RinexTimeSystem::kGalileo, -1, &t, &why));
  EXPECT_DOUBLE_EQ(t, kWalkGps);
  ASSERT_TRUE(RinexToGpsSeconds({2025, 8, 28, 17, 30, 21.748}, RinexTimeSystem::kUtc, 18, &t, &why));
  EXPECT_DOUBLE_EQ(t, kWalkGps);
  ASSERT_TRUE(RinexToGpsSeconds({2025, 8, 28, 17, 30, 21.748}, RinexTimeSystem::kGlonass, 18, &t, &why));
  EXPECT_DOUBLE_EQ(t, kWalkGps);
}

TEST(RinexTime, RefusesWhatIsNotATime) {
  std::string why;
  double t = 0.0;
  EXPECT_FALSE(RinexToGpsSeconds({2025, 8, 28, 17, 30, 21.0}, RinexTimeSystem::kGlonass, -1, &t, &why));
  EXPECT_NE(why.find("LEAP SECONDS"), std::string::npos) << why;
  EXPECT_FALSE(RinexToGpsSeconds({2025, 2, 29, 0, 0, 0.0}, RinexTimeSystem::kGps, -1, &t, &why));
  EXPECT_FALSE(RinexToGpsSeconds({1980, 1, 5, 0, 0, 0.0}, RinexTimeSystem::kGps, -1, &t, &why));
  EXPECT_FALSE(RinexToGpsSeconds({2025, 8, 28, 24, 0, 0.0}, RinexTimeSystem::kGps, -1, &t, &why));
  EXPECT_FALSE(RinexToGpsSeconds({2025, 8, 28, 0, 60, 0.0}, RinexTimeSystem::kGps, -1, &t, &why));
  EXPECT_FALSE(RinexToGpsSeconds({2025, 8, 28, 0, 0, 61.0}, RinexTimeSystem::kGps, -1, &t, &why));
  EXPECT_FALSE(RinexToGpsSeconds({2025, 8, 28, 0, 0, NAN}, RinexTimeSystem::kGps, -1, &t, &why));
}

TEST(RinexSatelliteId, ParsesAndPrints) {
  SatelliteId id;
  ASSERT_TRUE(ParseSatelliteId("G05", &id));
  EXPECT_EQ(id.system, GnssSystem::kGps);
  EXPECT_EQ(id.prn, 5);
  EXPECT_EQ(id.ToString(), "G05");
  ASSERT_TRUE(ParseSatelliteId("E19", &id));
  EXPECT_EQ(id.system, GnssSystem::kGalileo);
  ASSERT_TRUE(ParseSatelliteId("C23", &id));
  EXPECT_EQ(id.system, GnssSystem::kBeidou);
  EXPECT_EQ(id.prn, 23);
  ASSERT_TRUE(ParseSatelliteId("S33", &id));
  EXPECT_EQ(id.ToString(), "S33");
  ASSERT_TRUE(ParseSatelliteId("G 5", &id));
  EXPECT_EQ(id.ToString(), "G05");
  for (const char* bad : {"X01", "G00", "G5", "GAB", "g05", "G055", "", "R-1"}) {
    EXPECT_FALSE(ParseSatelliteId(bad, &id)) << bad;
  }
  SatelliteId a{GnssSystem::kGps, 3}, b{GnssSystem::kGps, 4};
  EXPECT_TRUE(a < b);
  EXPECT_TRUE(a != b);
}

TEST(RinexNumber, FortranExponentsAndBlanks) {
  double v = 0.0;
  bool blank = false;
  ASSERT_EQ(ParseRinexNumber(" -.516209285706D-03", &v, &blank), NumberStatus::kOk);
  EXPECT_DOUBLE_EQ(v, -0.516209285706e-3);
  EXPECT_FALSE(blank);
  ASSERT_EQ(ParseRinexNumber("      ", &v, &blank), NumberStatus::kOk);
  EXPECT_TRUE(blank);
  EXPECT_EQ(ParseRinexNumber("  12.3x", &v, &blank), NumberStatus::kBad);
  EXPECT_EQ(ParseRinexNumber("  1D400", &v, &blank), NumberStatus::kNonFinite);
}

// ---- Building files column by column

// One observation field: F14.3 value (nullopt: blank), LLI and SSI (-1: blank).
struct Obs {
  std::optional<double> value;
  int lli = -1;
  int ssi = -1;
};

std::string ObsLine(const std::string& sat, const std::vector<Obs>& obs) {
  std::string s = sat;
  for (const Obs& o : obs) {
    char buf[32];
    if (o.value) {
      std::snprintf(buf, sizeof(buf), "%14.3f", *o.value);
    } else {
      std::snprintf(buf, sizeof(buf), "%14s", "");
    }
    s += buf;
    s += o.lli < 0 ? ' ' : static_cast<char>('0' + o.lli);
    s += o.ssi < 0 ? ' ' : static_cast<char>('0' + o.ssi);
  }
  while (!s.empty() && s.back() == ' ') s.pop_back();  // writers may stop after the last value
  return s + "\n";
}

// A header line: content padded to 60 columns, then the label.
std::string H(const std::string& content, const std::string& label) {
  std::string s = content;
  s.resize(60, ' ');
  return s + label + "\n";
}

std::string EpochLine(int second, double frac, int flag, int count, const char* clock = nullptr) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "> 2025 08 28 17 30 %10.7f  %d%3d", second + frac, flag, count);
  std::string s = buf;
  if (clock != nullptr) {
    s.resize(41, ' ');
    s += clock;
  }
  return s + "\n";
}

const std::string kGpsTypes = H("G    4 C1C L1C D1C S1C", "SYS / # / OBS TYPES");

std::string Header(const std::string& time_system = "GPS", const std::string& extra = "",
                   const std::string& version = "     3.04", const std::string& gps_types = kGpsTypes) {
  return H(version + "           OBSERVATION DATA    M: Mixed", "RINEX VERSION / TYPE") +
         H(" -1276945.1807 -4717214.8258  4087225.2096", "APPROX POSITION XYZ") +
         H("        1.2500        0.0000        0.0000", "ANTENNA: DELTA H/E/N") + gps_types +
         H("E    2 C1C L1C", "SYS / # / OBS TYPES") +
         H("  2025    08    28    17    30   39.7480000     " + time_system, "TIME OF FIRST OBS") +
         H("     0.250", "INTERVAL") + extra + H("", "END OF HEADER");
}

// Epoch at 17:30:(39 + k/4).748 with G10 and E19; G10 holds k in its C/N0.
std::string Epoch(int k) {
  const double t = 39.748 + 0.25 * k;
  const int s = static_cast<int>(t);
  return EpochLine(s, t - s, 0, 2) +
         ObsLine("G10", {{20576396.770 + k, -1, 7}, {108129693.934, 1, 7}, {1064.326}, {40.0 + k}}) +
         ObsLine("E19", {{23205808.406}, {}});
}
// Epochs are 3 lines each after an 8-line header: epoch k's '>' is line 9 + 3k.
constexpr int kHeaderLines = 8;

std::string WriteTemp(const std::string& text, const std::string& name = "walk.obs") {
  const std::string path = test::MakeTempDir("rinex_obs") + "/" + name;
  test::WriteFile(path, text);
  return path;
}

struct ReadAll {
  std::vector<RinexObsEpoch> epochs;
  RinexObsStats stats;
  ConvertedFile file;
  RinexObsHeader header;
};

ReadAll Read(const std::string& path, InputErrorPolicy policy = InputErrorPolicy::kSkip) {
  InputOptions o;
  o.on_error = policy;
  RinexObsReader r(path, o);
  ReadAll all;
  RinexObsEpoch e;
  while (r.Next(&e)) all.epochs.push_back(e);
  all.stats = r.stats();
  all.file = r.file();
  all.header = r.header();
  return all;
}

TEST(RinexObs, HeaderAndEpochs) {
  const ReadAll all = Read(WriteTemp(Header() + Epoch(0) + Epoch(1)));
  EXPECT_EQ(all.header.version, 3.04);
  EXPECT_EQ(all.header.file_system, 'M');
  ASSERT_EQ(all.header.obs_types.at(GnssSystem::kGps).size(), 4u);
  EXPECT_EQ(all.header.obs_types.at(GnssSystem::kGps)[3], "S1C");
  EXPECT_EQ(all.header.obs_types.at(GnssSystem::kGalileo).size(), 2u);
  EXPECT_TRUE(all.header.has_approx_position);
  EXPECT_EQ(all.header.approx_position_ecef_m[1], -4717214.8258);
  EXPECT_EQ(all.header.antenna_delta_hen_m[0], 1.25);
  EXPECT_EQ(all.header.interval_s, 0.25);
  EXPECT_EQ(all.header.time_system, RinexTimeSystem::kGps);
  EXPECT_DOUBLE_EQ(all.header.first_obs_gps_s, kWalkGps);
  EXPECT_EQ(all.header.lines, static_cast<uint64_t>(kHeaderLines));
  ASSERT_EQ(all.epochs.size(), 2u);
  EXPECT_EQ(all.file.total_skipped(), 0u);
  const RinexObsEpoch& e = all.epochs[1];
  EXPECT_DOUBLE_EQ(e.gps_s, kWalkGps + 0.25);
  EXPECT_EQ(e.flag, 0);
  EXPECT_FALSE(e.has_clock_offset);
  EXPECT_EQ(e.line, static_cast<uint64_t>(kHeaderLines + 4));
  ASSERT_EQ(e.satellites.size(), 2u);
  const RinexSatelliteObs& g = e.satellites[0];
  EXPECT_EQ(g.sat.ToString(), "G10");
  ASSERT_EQ(g.obs.size(), 4u);
  EXPECT_DOUBLE_EQ(g.Find("C1C")->value, 20576397.770);
  EXPECT_EQ(g.Find("C1C")->ssi, 7);
  EXPECT_EQ(g.Find("C1C")->lli, 0);
  EXPECT_EQ(g.Find("L1C")->lli, 1);
  EXPECT_DOUBLE_EQ(g.Find("D1C")->value, 1064.326);
  EXPECT_DOUBLE_EQ(g.Find("S1C")->value, 41.0);
  const RinexSatelliteObs& gal = e.satellites[1];
  EXPECT_EQ(gal.obs.size(), 1u);  // L1C blank
  EXPECT_EQ(gal.Find("L1C"), nullptr);
  EXPECT_EQ(all.stats.epochs, 2u);
  EXPECT_EQ(all.stats.satellite_records, 4u);
}

TEST(RinexObs, ClockOffsetAndTypeContinuationLines) {
  // 15 types: the codes go on over a continuation line blank in columns 1-6.
  const std::string types =
      H("G   15 C1C L1C D1C S1C C2L L2L D2L S2L C5Q L5Q D5Q S5Q C1W", "SYS / # / OBS TYPES") +
      H("       L1W D1W", "SYS / # / OBS TYPES");
  const std::string header = Header("GPS", "", "     3.04", types);
  std::vector<Obs> obs(15);
  obs[14] = {-12.5, 0, 9};
  const ReadAll all =
      Read(WriteTemp(header + EpochLine(39, 0.748, 1, 1, "-0.123456789012") + ObsLine("G01", obs)));
  ASSERT_EQ(all.header.obs_types.at(GnssSystem::kGps).size(), 15u);
  EXPECT_EQ(all.header.obs_types.at(GnssSystem::kGps)[13], "L1W");
  ASSERT_EQ(all.epochs.size(), 1u) << FormatIssueCounts("skipped", all.file.skipped, all.file.issues);
  EXPECT_EQ(all.epochs[0].flag, 1);
  EXPECT_TRUE(all.epochs[0].has_clock_offset);
  EXPECT_DOUBLE_EQ(all.epochs[0].receiver_clock_offset_s, -0.123456789012);
  ASSERT_EQ(all.epochs[0].satellites[0].obs.size(), 1u);
  EXPECT_EQ(all.epochs[0].satellites[0].Find("D1W")->value, -12.5);
  EXPECT_EQ(all.epochs[0].satellites[0].Find("D1W")->ssi, 9);
}

TEST(RinexObs, EventsAndCycleSlipRecordsAreSkippedAndCounted) {
  const std::string text = Header() + Epoch(0) + EpochLine(40, 0.0, 2, 0) +  // start moving: no records
                           ">                              4  2\n" +            // header information follows
                           H("G    2 C1C S1C", "SYS / # / OBS TYPES") + H("a comment", "COMMENT") +
                           EpochLine(40, 0.0, 6, 1) + ObsLine("G10", {{1.0}, {2.0, 1}}) +  // a cycle slip
                           EpochLine(40, 0.0, 0, 1) + ObsLine("G10", {{20576400.0}, {45.0}});
  const ReadAll all = Read(WriteTemp(text));
  EXPECT_EQ(all.file.total_skipped(), 0u) << FormatIssueCounts("skipped", all.file.skipped, all.file.issues);
  ASSERT_EQ(all.epochs.size(), 2u);
  EXPECT_EQ(all.stats.event_epochs, 2u);
  EXPECT_EQ(all.stats.event_lines, 2u);
  EXPECT_EQ(all.stats.cycle_slip_epochs, 1u);
  EXPECT_EQ(all.stats.cycle_slip_lines, 1u);
  // The event's SYS / # / OBS TYPES applies from there on.
  EXPECT_EQ(all.epochs[1].satellites[0].Find("S1C")->value, 45.0);
}

TEST(RinexObs, GzipAndGlonassTimeWithLeapSeconds) {
  const std::string dir = test::MakeTempDir("rinex_obs_gz");
  const std::string path = dir + "/walk.obs.gz";
  const std::string text = Header("GLO", H("    18", "LEAP SECONDS")) + Epoch(0);
  gzFile f = gzopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  gzwrite(f, text.data(), static_cast<unsigned>(text.size()));
  gzclose(f);
  const ReadAll all = Read(path);
  EXPECT_EQ(all.header.leap_seconds, 18);
  EXPECT_EQ(all.header.time_system, RinexTimeSystem::kGlonass);
  ASSERT_EQ(all.epochs.size(), 1u);
  EXPECT_DOUBLE_EQ(all.epochs[0].gps_s, kWalkGps + 18.0);
}

void ExpectRefused(const std::string& text, const std::string& where_what) {
  const std::string path = WriteTemp(text);
  for (const InputErrorPolicy policy : {InputErrorPolicy::kSkip, InputErrorPolicy::kStop}) {
    try {
      Read(path, policy);
      ADD_FAILURE() << "not refused: " << where_what;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + ":" + where_what), std::string::npos) << e.what();
    }
  }
}

TEST(RinexObs, RefusesHeadersItCannotRead) {
  ExpectRefused(Header("GPS", "", "     2.11") + Epoch(0), "1: RINEX version 2.11");
  ExpectRefused(Header("GPS", "", "     4.00") + Epoch(0), "1: RINEX version 4.00");
  ExpectRefused("hello\n", "1: not a RINEX file");
  ExpectRefused("", "1: empty file");
  std::string nav = Header();
  nav.replace(nav.find("OBSERVATION DATA"), 16, "N: GNSS NAV DATA");
  ExpectRefused(nav, "1: not a RINEX observation file");
  std::string no_end = Header();
  no_end.erase(no_end.find(H("", "END OF HEADER")));
  ExpectRefused(no_end, "8: the header has no END OF HEADER");
  ExpectRefused(Header("GLO") + Epoch(0), "6: TIME OF FIRST OBS: time system GLO needs GPS − UTC");
  ExpectRefused(Header("XYZ") + Epoch(0), "6: TIME OF FIRST OBS: time system");
  std::string short_types = Header();
  short_types.replace(short_types.find("G    4"), 6, "G    5");
  ExpectRefused(short_types, "5: SYS / # / OBS TYPES of G announces 5 types and lists 4");
  std::string bad_code = Header();
  bad_code.replace(bad_code.find("C1C L1C D1C"), 3, "Q1C");
  ExpectRefused(bad_code, "4: SYS / # / OBS TYPES: 'Q1C'");
}

// One kind of damage: the file, the reason and line it must report, and the epochs the skip policy keeps.
struct DamageCase {
  const char* name;
  std::string text;
  const char* reason;
  int line;
  size_t epochs_kept;
};

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? s : s.replace(at, from.size(), to);
}

std::vector<DamageCase> DamageCases() {
  const std::string h = Header();
  const int e1 = kHeaderLines + 4;  // epoch 1's '>' line
  const std::string cut_epoch = Epoch(2).substr(0, Epoch(2).find("E19"));
  const std::string three = Epoch(0) + Epoch(1) + Epoch(2);
  return {
      {"bad_value", h + Replace(three, "108129693.934", "108129x93.934"), "bad_number", kHeaderLines + 2, 3},
      {"bad_lli", h + Replace(three, "108129693.9341", "108129693.934x"), "bad_number", kHeaderLines + 2, 3},
      {"non_finite", h + Replace(three, "  1064.326", "    1e+999"), "non_finite", kHeaderLines + 2, 3},
      {"bad_satellite", h + Replace(three, "E19", "X19"), "unknown_type", kHeaderLines + 3, 3},
      {"system_without_types", h + Replace(three, "E19", "C19"), "unknown_type", kHeaderLines + 3, 3},
      {"extra_fields", h + Replace(three, "E19  23205808.406\n", "E19  23205808.406                  12.0\n"),
       "extra_fields", kHeaderLines + 3, 3},
      {"duplicate_satellite", h + Replace(three, "E19", "G10"), "duplicate", kHeaderLines + 3, 3},
      {"bad_epoch_date", h + Epoch(0) + Replace(Epoch(1), "08 28", "13 28") + Epoch(2), "bad_time", e1, 2},
      {"bad_epoch_flag", h + Epoch(0) + Replace(Epoch(1), "  0  2", "  9  2") + Epoch(2), "bad_number", e1, 2},
      {"bad_clock", h + Epoch(0) + Replace(Epoch(1), "  0  2", "  0  2      -0.12x") + Epoch(2), "bad_number", e1,
       2},
      {"missing_satellite_lines", h + Epoch(0) + cut_epoch + Epoch(1), "missing_fields", kHeaderLines + 4, 2},
      {"duplicate_epoch", h + Epoch(0) + Epoch(0) + Epoch(1), "duplicate", e1, 2},
      {"out_of_order", h + Epoch(1) + Epoch(0) + Epoch(2), "out_of_order", e1, 2},
      {"stray_line", h + Epoch(0) + "garbage\n" + Epoch(1), "unknown_type", kHeaderLines + 4, 2},
      {"truncated_final_epoch", h + Epoch(0) + Epoch(1) + cut_epoch, "truncated", kHeaderLines + 7, 2},
      {"truncated_final_line", h + Epoch(0) + Epoch(1) + cut_epoch.substr(0, cut_epoch.size() - 30), "truncated",
       kHeaderLines + 7, 2},
      {"truncated_last_satellite", h + three.substr(0, three.size() - 5), "truncated", kHeaderLines + 9, 3},
      {"bad_interval_line", Replace(h, "     0.250", "     0.2x0") + Epoch(0), "bad_number", 7, 1},
      {"bad_approx_position", Replace(h, "-4717214.8258", "-4717214.82x8") + Epoch(0), "bad_number", 2, 1},
      {"blank_antenna_delta",
       Replace(h, "1.2500        0.0000        0.0000", "1.2500" + std::string(28, ' ')) + Epoch(0), "missing_fields",
       3, 1},
      {"bad_leap_seconds", Header("GPS", H("    1x", "LEAP SECONDS")) + Epoch(0), "bad_number", 8, 1},
  };
}

TEST(RinexObs, DamageIsCountedOrStops) {
  for (const DamageCase& c : DamageCases()) {
    SCOPED_TRACE(c.name);
    const std::string path = WriteTemp(c.text, std::string(c.name) + ".obs");
    const ReadAll all = Read(path);
    EXPECT_EQ(all.file.total_skipped(), 1u) << FormatIssueCounts("skipped", all.file.skipped, all.file.issues);
    ASSERT_EQ(all.file.skipped.count(c.reason), 1u) << FormatIssueCounts("skipped", all.file.skipped, all.file.issues);
    ASSERT_FALSE(all.file.issues.empty());
    EXPECT_EQ(all.file.issues[0].line, static_cast<uint64_t>(c.line)) << all.file.issues[0].detail;
    EXPECT_EQ(all.epochs.size(), c.epochs_kept);
    for (const RinexObsEpoch& e : all.epochs) {
      for (const RinexSatelliteObs& s : e.satellites) {
        for (const RinexObservation& o : s.obs) EXPECT_TRUE(std::isfinite(o.value));
      }
    }
    try {
      Read(path, InputErrorPolicy::kStop);
      ADD_FAILURE() << "no InputError under stop";
    } catch (const InputError& e) {
      const std::string want = path + ":" + std::to_string(c.line) + ": ";
      EXPECT_EQ(std::string(e.what()).rfind(want, 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.reason), std::string::npos) << e.what();
    }
  }
}

TEST(RinexObs, TooManyDamagedLinesStop) {
  std::string text = Header();
  for (int k = 0; k < 5; ++k) text += "garbage\n";
  InputOptions o;
  o.max_errors = 3;
  RinexObsReader r(WriteTemp(text), o);
  RinexObsEpoch e;
  EXPECT_THROW(r.Next(&e), InputError);
}

// The bundled excerpt: the header and first 8 epochs of a real u-blox walk (data/rinex/README.md).
TEST(RinexObs, WalkExcerpt) {
  const ReadAll all = Read(std::string(GINS_TEST_DATA_DIR) + "/rinex/walk_excerpt.obs", InputErrorPolicy::kStop);
  EXPECT_EQ(all.header.version, 3.04);
  EXPECT_EQ(all.header.obs_types.at(GnssSystem::kGps).size(), 12u);
  EXPECT_EQ(all.header.obs_types.at(GnssSystem::kGalileo).size(), 12u);
  EXPECT_EQ(all.header.obs_types.at(GnssSystem::kBeidou).size(), 12u);
  EXPECT_EQ(all.header.obs_types.at(GnssSystem::kSbas).size(), 4u);
  EXPECT_EQ(all.header.obs_types.at(GnssSystem::kBeidou)[0], "C5P");
  EXPECT_EQ(all.header.approx_position_ecef_m[0], -1276945.1807);
  EXPECT_DOUBLE_EQ(all.header.first_obs_gps_s, kWalkGps);
  ASSERT_EQ(all.epochs.size(), 8u);
  EXPECT_EQ(all.stats.satellite_records, 8u * 28u);
  for (size_t k = 0; k < all.epochs.size(); ++k) {
    const RinexObsEpoch& e = all.epochs[k];
    EXPECT_NEAR(e.gps_s, kWalkGps + 0.25 * static_cast<double>(k), 1e-6);
    int n[4] = {0, 0, 0, 0};
    for (const RinexSatelliteObs& s : e.satellites) {
      n[0] += s.sat.system == GnssSystem::kGps;
      n[1] += s.sat.system == GnssSystem::kGalileo;
      n[2] += s.sat.system == GnssSystem::kBeidou;
      n[3] += s.sat.system == GnssSystem::kSbas;
    }
    EXPECT_EQ(n[0], 7);
    EXPECT_EQ(n[1], 8);
    EXPECT_EQ(n[2], 10);
    EXPECT_EQ(n[3], 3);
  }
  const RinexObsEpoch& e = all.epochs[0];
  const RinexSatelliteObs& g10 = e.satellites[0];
  EXPECT_EQ(g10.sat.ToString(), "G10");
  EXPECT_DOUBLE_EQ(g10.Find("C1C")->value, 20576396.770);
  EXPECT_DOUBLE_EQ(g10.Find("L1C")->value, 108129693.934);
  EXPECT_DOUBLE_EQ(g10.Find("D1C")->value, 1064.326);
  EXPECT_DOUBLE_EQ(g10.Find("S1C")->value, 51.0);
  EXPECT_DOUBLE_EQ(g10.Find("L5Q")->value, 80746217.480);
  const RinexSatelliteObs& g18 = e.satellites[1];
  EXPECT_EQ(g18.sat.ToString(), "G18");
  EXPECT_DOUBLE_EQ(g18.Find("L1C")->value, 114955809.983);
  EXPECT_EQ(g18.Find("L1C")->lli, 1);
  EXPECT_EQ(g18.Find("L2L"), nullptr);  // blank in the file
  const RinexSatelliteObs* g08 = nullptr;
  const RinexSatelliteObs* e14 = nullptr;
  for (const RinexSatelliteObs& s : e.satellites) {
    if (s.sat.ToString() == "G08") g08 = &s;
    if (s.sat.ToString() == "E14") e14 = &s;
  }
  ASSERT_NE(g08, nullptr);
  EXPECT_EQ(g08->Find("C1C"), nullptr);  // no L1 signal: the first 64 columns blank
  EXPECT_DOUBLE_EQ(g08->Find("C2L")->value, 22846861.832);
  ASSERT_NE(e14, nullptr);
  EXPECT_EQ(e14->Find("L5Q"), nullptr);
  ASSERT_NE(e14->Find("L6B"), nullptr);
  EXPECT_DOUBLE_EQ(e14->Find("L6B")->value, 83069836.368);
  EXPECT_EQ(e14->Find("L6B")->lli, 2);  // half-cycle ambiguity
  ASSERT_NE(e14->Find("D6B"), nullptr);
  EXPECT_DOUBLE_EQ(e14->Find("D6B")->value, -3057.253);
}

}  // namespace
}  // namespace gins
